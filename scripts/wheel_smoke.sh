#!/usr/bin/env bash
# Build the sdist and the wheel (the wheel is built from the sdist, so both carry the package
# data), install the wheel into a fresh virtual environment with its dependencies from the
# pinned requirements, and smoke-test it outside the source tree: the main job, a 3D page, a
# sweep and the README's Python API. Called by .ci/run after `make test`.
#
#   scripts/wheel_smoke.sh [PYTHON]     (default: .venv/bin/python, which has `build`)
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
PY=${1:-$ROOT/.venv/bin/python}
OUT=$ROOT/build/release
rm -rf "$OUT" && mkdir -p "$OUT/dist" "$OUT/run"

VERSION=$("$PY" -c "import ast,sys; t=ast.parse(open('kinestat/__init__.py').read());\
print(next(n.value.value for n in t.body if isinstance(n, ast.Assign)\
 and n.targets[0].id == '__version__'))")
echo "wheel_smoke: building kinestat $VERSION (sdist, then the wheel from it)"
"$PY" -m build --outdir "$OUT/dist" . >"$OUT/build.log" 2>&1 || { cat "$OUT/build.log"; exit 1; }
WHEEL=$(ls "$OUT"/dist/kinestat-"$VERSION"-*.whl)
SDIST=$OUT/dist/kinestat-$VERSION.tar.gz
test -f "$SDIST"

# every file of the package's data (embedded models, decks, calibrations, vendored three.js)
# is in both archives
"$PY" - "$WHEEL" "$SDIST" <<'EOF'
import subprocess, sys, tarfile, zipfile
tracked = subprocess.run(["git", "ls-files", "kinestat/data"], capture_output=True, text=True,
                         check=True).stdout.split()
wheel = set(zipfile.ZipFile(sys.argv[1]).namelist())
sdist = {n.split("/", 1)[1] for n in tarfile.open(sys.argv[2]).getnames() if "/" in n}
missing = [f for f in tracked if f not in wheel or f not in sdist]
if not tracked or missing:
    sys.exit(f"wheel_smoke: package data missing from the archives: {missing or 'no data'}")
print(f"wheel_smoke: {len(tracked)} data files in the wheel and the sdist")
EOF

# a fresh environment: no system site-packages, dependencies pinned, the wheel without the tree
python3 -m venv "$OUT/venv"
V=$OUT/venv/bin
"$V/pip" install -q --upgrade pip
"$V/pip" install -q -r requirements/run.txt
"$V/pip" install -q --no-deps "$WHEEL"

cd "$OUT/run"   # outside the source tree: only the installed wheel can be imported
export PYTHONPATH=
K=$V/kinestat
"$V/python" -c "import kinestat, sys; assert '/venv/' in kinestat.__file__, kinestat.__file__"
test "$("$K" --version)" = "kinestat $VERSION"
"$K" control >control.txt
grep -q "log: " control.txt
"$K" view model puma762 --html x.html --no-open
grep -q "OrbitControls" x.html   # the vendored three.js bundle is inlined
"$K" sweep workspace --model puma762 --grid 2 --output sweep >sweep.txt
grep -q "reach_max" sweep.txt

# the README's Python API block, run as written (its TOML file written from an embedded model)
"$V/python" -c "import kinestat; from kinestat.io.model_toml import write_model;\
 write_model(kinestat.load('puma560'), 'my_arm.toml')"
"$V/python" - "$ROOT/README.md" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
block = text.split("## The Python API", 1)[1]
code = re.search(r"```python\n(.*?)```", block, re.S).group(1)
namespace = {}
exec(compile(code, "README.md", "exec"), namespace)
import numpy as np
T, res = namespace["T"], namespace["res"]
assert T.shape == (1, 4, 4) and bool(np.all(res.success)), "README API"
print("wheel_smoke: the README's Python API runs")
EOF
echo "wheel_smoke: kinestat $VERSION wheel installed in a fresh venv and smoke-tested: ok"
