"""Command-line fault campaign: bad input to every ``kinestat`` command, checked against the
CLI's contract (docs/cli.md, docs/reliability.md).

Usage::

    .venv/bin/python scripts/cli_fuzz_campaign.py [--quick] [--no-signals] [--only PREFIX]

For every bad input the contract is: exit status 2, exactly one stderr line
``kinestat: error: ...`` that names the option (or the file) at fault, no traceback, and no file
left behind (in the working directory or at the output path given). Good input at the edges
(the smallest step count, paths with blanks and non-ASCII letters, angles at their limits) must
exit 0. Ctrl-C: a run ends with one line, status 130 (control: 2, its documented status for a
stop, with a cycle log ending ``fault``, ``end``; the simulators: 0).

The table cases run in one child process through :func:`kinestat.cli.main.main` (each in a
fresh working directory, under an alarm); the Ctrl-C cases run ``kinestat`` as a subprocess.
Violations are printed one per line with their class, then a count per class. ``--quick`` runs
a sample (every class, every command) in well under a minute once the kernels are compiled.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

P16 = "1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1"
PTS = "0,0,0,0,0,1,1,0,0"

# (class, argv, expect, mention): expect "error" (the contract of a bad input) or "ok";
# mention: a text the error line must hold (the option or the file at fault). ``{fx}`` is the
# fixtures folder, ``{deck}`` an embedded guidance deck, ``{out}`` a path in the case's own
# working directory that must not exist afterwards.
CASES: list[tuple[str, list[str], str, str | None]] = [
    # -- malformed lists, wrong counts, non-finite numbers
    ("list", ["fk", "puma762", "--q", "1,,2,3,4,5"], "error", "--q"),
    ("list", ["fk", "puma762", "--q", "1;2;3;4;5;6"], "error", "--q"),
    ("list", ["fk", "puma762", "--q", "1,2,3,4,5,6,7"], "error", "--q"),
    ("list", ["fk", "puma762", "--q", ""], "error", "--q"),
    ("nonfinite", ["fk", "puma762", "--q-deg", "nan,0,0,0,0,0"], "error", "--q-deg"),
    ("nonfinite", ["fk", "puma762", "--q", "0,0,0,0,0,inf"], "error", "--q"),
    ("list", ["fk", "puma762", "--q", "0,0,0,0,0,0", "--tool-offset", "1,2"], "error",
     "--tool-offset"),
    ("choice", ["fk", "puma762", "--q", "0,0,0,0,0,0", "--euler", "XYZW"], "error", "--euler"),
    ("pair", ["fk", "puma762", "--q", "0,0,0,0,0,0", "--q-deg", "0,0,0,0,0,0"], "error",
     "--q"),
    ("type", ["fk", "{urdf}", "--tip", "tool0", "--scale", "abc", "--q", "0,0,0,0,0,0"],
     "error", "--scale"),
    ("pair", ["fk", "puma762", "--q", "0,0,0,0,0,0", "--length-unit", "mm"], "error",
     "--length-unit"),
    ("pair", ["fk", "puma762", "--q", "0,0,0,0,0,0", "--scale", "2"], "error", "--scale"),
    ("list", ["screw", "--pose1", P16, "--pose2", "1,2,3"], "error", "--pose2"),
    ("list", ["screw", "--points1", PTS, "--points2", "0,0,0,0,0,1,1,0"], "error", "--points2"),
    ("pair", ["screw", "--pose1", P16, "--pose2", P16, "--points1", PTS, "--points2", PTS],
     "error", "--points1"),
    ("list", ["platform", "fk", "--legs", "60,60,60"], "error", "--legs"),
    ("range", ["platform", "fk", "--legs", "0,60,60,60,60,60"], "error", "--legs"),
    ("list", ["platform", "statics", "--pose", "home", "--wrench", "1,2,3,4,5,inf"], "error",
     "--wrench"),
    ("choice", ["platform", "stiffness", "--twist-order", "bogus"], "error", "--twist-order"),
    ("list", ["platform", "decompose", "--twist", "1,2,3,4,5,6", "--contact", "1,2,3"],
     "error", "--contact"),
    ("list", ["ik", "puma762", "--tool-point", "nan,200,300", "--s6", "0,0,1", "--a67",
              "1,0,0"], "error", "--tool-point"),
    ("range", ["ik", "puma560", "--pose", P16, "--restarts", "-1"], "error", "--restarts"),
    ("range", ["ik", "puma560", "--pose", P16, "--max-iter", "0"], "error", "--max-iter"),
    ("range", ["ik", "puma560", "--pose", P16, "--seed", "-3"], "error", "--seed"),
    ("choice", ["ik", "puma560", "--pose", P16, "--limits", "bogus"], "error", "--limits"),
    ("pair", ["ik", "puma560", "--pose", P16, "--current-deg", "1,2"], "error",
     "--current-deg"),
    ("type", ["ik", "puma560", "--pose", P16, "--all", "--lock", "1=abc"], "error", "--lock"),
    ("list", ["guide", "puma560", "--to", "1,2,3"], "error", "--to"),
    ("range", ["guide", "puma560", "--to-pose", P16, "--steps", "-2"], "error", "--steps"),
    ("range", ["guide", "puma560", "--to-pose", P16, "--speed", "nan"], "error", "--speed"),
    ("range", ["guide", "puma560", "--to-pose", P16, "--cond-limit", "0"], "error",
     "--cond-limit"),
    ("choice", ["guide", "puma560", "--to-pose", P16, "--type", "bogus"], "error", "--type"),
    ("empty", ["guide", "puma560", "--command", ""], "error", "--command"),
    ("list", ["disp", "{deck}", "--steps", "1,,2"], "error", "--steps"),
    ("type", ["disp", "{deck}", "--steps", "1.5"], "error", "--steps"),
    ("range", ["disp", "{deck}", "--cond-limit", "nan"], "error", "--cond-limit"),
    ("choice", ["disp", "{deck}", "--singular", "bogus"], "error", "--singular"),
    ("pair", ["disp", "{deck}", "--settle", "--no-settle"], "error", "--settle"),
    ("pair", ["disp", "{deck}", "--damped", "--singular", "stop"], "error", "--damped"),
    ("pair", ["guide", "puma560", "--to-pose", P16, "--damped", "--singular", "bogus"], "error",
     "--singular"),
    ("pair", ["ik", "puma762", "--tool-point", "100,200,300", "--s6", "0,0,1", "--a67", "1,0,0",
              "--q0-deg", "0,0,0,0,0,0"], "error", "--q0-deg"),
    ("pair", ["sweep", "workspace", "--samples", "2", "--scheduler", "tcp://127.0.0.1:1",
              "--workers", "2", "--output", "{out}"], "error", "--workers"),
    ("range", ["control", "--force", "nan", "--no-plot"], "error", "--force"),
    ("range", ["control", "--align-tol-deg", "200", "--no-plot"], "error", "--align-tol-deg"),
    ("range", ["control", "--task", "follow", "--travel", "-1", "--no-plot"], "error",
     "--travel"),
    ("range", ["control", "--task", "follow", "--tilt-deg", "100", "--no-plot"], "error",
     "--tilt-deg"),
    ("choice", ["control", "--serial-format", "bogus", "--no-plot"], "error",
     "--serial-format"),
    ("range", ["control", "--task", "follow", "--travel-dir", "0,0,0", "--no-plot"], "error",
     "--travel-dir"),
    ("range", ["control", "--task", "follow", "--travel-step", "0", "--no-plot"], "error",
     "--travel-step"),
    ("range", ["control", "--task", "follow", "--probe-span", "100", "--no-plot"], "error",
     "--probe-span"),
    ("range", ["sweep", "workspace", "--samples", "2", "--workers", "100000", "--output",
               "{out}"], "error", "--workers"),
    ("pair", ["control", "--plot", "{out}", "--no-plot"], "error", "--plot"),
    ("list", ["control", "--start", "1,2", "--no-plot"], "error", "--start"),
    ("range", ["control", "--samples", "0", "--no-plot"], "error", "--samples"),
    ("choice", ["control", "--method", "bogus", "--no-plot"], "error", "--method"),
    ("range", ["home", "--galil", "127.0.0.1:1", "--samples", "0"], "error", "--samples"),
    ("type", ["home", "--galil", "bogus"], "error", "--galil"),
    ("range", ["sim", "galil", "--port", "-1", "--duration", "0.1"], "error", "--port"),
    ("range", ["sim", "galil", "--rate", "0", "--duration", "0.1"], "error", "--rate"),
    ("range", ["sim", "encoders", "--rate", "0", "--duration", "0.1"], "error", "--rate"),
    ("type", ["sim", "encoders", "--counts", "1.5,0,0,0,0,0", "--duration", "0.1"], "error",
     "--counts"),
    ("range", ["view", "model", "puma560", "--no-open", "--port", "70000", "--serve"], "error",
     "--port"),
    ("choice", ["view", "model", "puma560", "--no-open", "--meshes", "bogus"], "error",
     "--meshes"),
    ("range", ["sweep", "workspace", "--grid", "1", "--output", "{out}", "--quiet"], "error",
     "--grid"),
    ("range", ["sweep", "workspace", "--samples", "3", "--timeout", "nan", "--output", "{out}",
               "--quiet"], "error", "--timeout"),
    ("range", ["sweep", "platform-range", "--grid", "2", "--range-deg", "-1,2,3", "--output",
               "{out}", "--quiet"], "error", "--range-deg"),
    ("range", ["sweep", "platform-design", "--grid", "2", "--height", "50:70", "--base-side",
               "-5", "--output", "{out}", "--quiet"], "error", "--base-side"),
    ("range", ["sweep", "platform-design", "--grid", "2", "--height", "0:70", "--output",
               "{out}", "--quiet"], "error", "--height"),
    ("range", ["sweep", "tolerance", "--samples", "2", "--sigma-k", "-1", "--output", "{out}",
               "--quiet"], "error", "--sigma-k"),
    # -- files: missing, a directory, empty, binary, truncated, the wrong format, empty names
    ("file", ["fk", "{fx}/missing.toml", "--q", "0,0,0,0,0,0"], "error", "missing.toml"),
    ("file", ["fk", "{fx}", "--q", "0,0,0,0,0,0"], "error", "{fx}"),
    ("file", ["fk", "{fx}/binary.toml", "--q", "0,0,0,0,0,0"], "error", "binary.toml"),
    ("file", ["fk", "{fx}/truncated.toml", "--q", "0,0,0,0,0,0"], "error", "truncated.toml"),
    ("file", ["fk", "{fx}/truncated.urdf", "--q", "0,0,0,0,0,0"], "error", "truncated.urdf"),
    ("format", ["fk", "{fx}/robot.toml", "--q", "0,0,0,0,0,0"], "error", "robot.toml"),
    ("empty", ["fk", "", "--q", "0,0,0,0,0,0"], "error", "'model'"),
    ("file", ["disp", "{fx}/binary.toml"], "error", "binary.toml"),
    ("file", ["disp", "{fx}/empty.toml"], "error", "empty.toml"),
    ("file", ["disp", "{fx}/truncated.dat"], "error", "truncated.dat"),
    ("format", ["disp", "{urdf}"], "error", ".urdf"),
    ("empty", ["disp", ""], "error", "'deck'"),
    ("empty", ["dh-from-axes", ""], "error", "'file'"),
    ("format", ["dh-from-axes", "{fx}/robot.toml"], "error", "robot.toml"),
    ("file", ["screw", "--pose1", P16, "--pose2", "{fx}/binary.toml"], "error", "binary.toml"),
    ("file", ["screw", "--pose1", P16, "--pose2", "{fx}/missing.json"], "error", "--pose2"),
    ("empty", ["platform", "info", "--platform", ""], "error", "--platform"),
    ("format", ["platform", "info", "--platform", "{fx}/robot.toml"], "error", "robot.toml"),
    ("file", ["guide", "puma560", "--commands", "{fx}/binary.toml"], "error", "binary.toml"),
    ("file", ["view", "log", "{fx}/truncated.jsonl", "--no-open", "--html", "{out}"], "error",
     "truncated.jsonl"),
    ("file", ["view", "log", "{fx}", "--no-open", "--html", "{out}"], "error", "{fx}"),
    ("file", ["control", "--calibration", "{fx}/binary.toml", "--no-plot"], "error",
     "binary.toml"),
    ("empty", ["control", "--log", "", "--no-plot"], "error", "--log"),
    ("empty", ["sweep", "tolerance", "--samples", "2", "--platform", "", "--output", "{out}"],
     "error", "--platform"),
    # -- outputs that cannot be written, or empty output names: refused before any work
    ("output", ["screw", "--pose1", P16, "--pose2", P16, "--view", "--html", "/proc/x.html"],
     "error", "--html"),
    ("empty", ["screw", "--pose1", P16, "--pose2", P16, "--view", "--html", ""], "error",
     "--html"),
    ("output", ["view", "model", "puma560", "--no-open", "--html", "{fx}/binary.toml/x.html"],
     "error", "--html"),
    ("empty", ["view", "model", "puma560", "--no-open", "--html", ""], "error", "--html"),
    ("output", ["platform", "fk", "--legs", "70,70,70,70,70,70", "--html", "/proc/x.html"],
     "error", "--html"),
    ("output", ["disp", "{deck}", "--plot", "/proc/x"], "error", "--plot"),
    ("empty", ["disp", "{deck}", "--plot", ""], "error", "--plot"),
    ("output", ["guide", "puma560", "--to-pose", P16, "--html", "/proc/x.html"], "error",
     "--html"),
    ("output", ["control", "--plot", "/proc/x"], "error", "--plot"),
    ("output", ["control", "--log", "/proc/x.jsonl", "--no-plot"], "error", "--log"),
    ("output", ["dh-from-axes", "{fx}/axes.toml", "--write-model", "/proc/m.toml"], "error",
     "--write-model"),
    ("output", ["sweep", "workspace", "--samples", "3", "--output", "/proc/o", "--quiet"],
     "error", "--output"),
    ("empty", ["sweep", "workspace", "--samples", "3", "--output", "", "--quiet"], "error",
     "--output"),
    # -- good input at the edges: accepted
    ("edge", ["fk", "{fx}/dir with blanks/mödel ü.toml", "--q", "-0,0,0,0,0,0"], "ok", None),
    ("edge", ["fk", "puma762", "--q-deg", "-180,0,0,0,0,180"], "ok", None),
    ("edge", ["disp", "{deck}", "--steps", "0", "--plot", "{fx}/plots with blanks"], "ok",
     None),
    ("edge", ["platform", "ik", "--pose", "HOME"], "ok", None),
    ("edge", ["control", "--align-tol-deg", "90", "--max-iterations", "1", "--no-plot",
              "--log", "{fx}/dir with blanks/ü log.jsonl"], "any", None),
    ("edge", ["view", "model", "puma560", "--no-open", "--html",
              "{fx}/dir with blanks/ü view.html"], "ok", None),
]

QUICK = {"list", "nonfinite", "choice", "pair", "empty", "output", "edge", "file", "format",
         "range", "type"}


def _fixtures(fx: Path) -> dict[str, str]:
    import kinestat
    from tests.urdf_arms import arm_path
    data = Path(kinestat.__file__).parent / "data"
    urdf = str(arm_path("ur5"))
    (fx / "binary.toml").write_bytes(b"\x00\x01\xff\xfe garbage \x80")
    (fx / "empty.toml").write_text("")
    model = (data / "models" / "puma560.toml").read_text()
    (fx / "truncated.toml").write_text(model[: model.index("[[joints]]") + 20])
    (fx / "truncated.urdf").write_text(Path(urdf).read_text()[:3000])
    (fx / "robot.toml").write_text(Path(urdf).read_text())  # a URDF where TOML is expected
    deck = (data / "decks" / "illustration5.dat").read_text().splitlines(keepends=True)
    (fx / "truncated.dat").write_text("".join(deck[:3]))
    (fx / "truncated.jsonl").write_text('{"type": "start", "config": {"a": 1')
    sp = fx / "dir with blanks"
    sp.mkdir()
    shutil.copy(data / "models" / "puma560.toml", sp / "mödel ü.toml")
    (fx / "axes.toml").write_text(
        'length_unit = "m"\n[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 1]\n'
        '[[axes]]\npoint = [1, 0, 0]\ndirection = [0, 0, 1]\n')
    return {"fx": str(fx), "urdf": urdf, "deck": "illustration5"}


def _fill(arg: str, subs: dict[str, str]) -> str:
    for k, v in subs.items():
        arg = arg.replace("{" + k + "}", v)
    return arg


def run_case(argv: list[str], expect: str, mention: str | None, subs: dict[str, str],
             alarm: float) -> list[str]:
    """The contract violations of one call (empty: none), run in-process in a fresh folder."""
    from kinestat.cli.main import main

    work = Path(tempfile.mkdtemp(prefix="case-"))
    out_path = work / "out-target"
    subs = {**subs, "out": str(out_path)}
    argv = [_fill(a, subs) for a in argv]
    mention = None if mention is None else _fill(mention, subs)
    before = set(os.listdir(subs["fx"])) | {"dir with blanks"}
    old = os.getcwd()
    os.chdir(work)
    out, err = io.StringIO(), io.StringIO()
    problems = []
    t0 = time.monotonic()
    signal.setitimer(signal.ITIMER_REAL, alarm)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
    except _Alarm:
        problems.append(f"no answer within {alarm:g} s")
        code = None
    except BaseException:  # noqa: BLE001 - an escaping exception is what the campaign finds
        problems.append("exception escaped: " + traceback.format_exc().strip().splitlines()[-1])
        code = None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        os.chdir(old)
    lines = [ln for ln in err.getvalue().splitlines()
             if ln.strip() and not ln.startswith("kinestat: compiling")]
    text = err.getvalue() + out.getvalue()
    if "Traceback (most recent call last)" in text:
        problems.append("traceback printed")
    if expect == "error" and code is not None:
        errors = [ln for ln in lines if ln.startswith("kinestat: error:")]
        if code != 2:
            problems.append(f"exit {code}, not 2")
        if len(lines) != 1 or len(errors) != 1:
            problems.append(f"{len(lines)} stderr lines, not one error line: {lines[:3]}")
        elif mention is not None and mention not in errors[0]:
            problems.append(f"error does not name {mention!r}: {errors[0]}")
        left = sorted(os.listdir(work))
        if left:
            problems.append(f"left behind: {left}")
        after = set(os.listdir(subs["fx"])) - before
        if after:
            problems.append(f"left in fixtures: {sorted(after)}")
    elif expect == "ok" and code != 0:
        problems.append(f"good input refused (exit {code}): {lines[-1:] or ''}")
    elif expect == "any" and code not in (0, 2):
        problems.append(f"exit {code}")
    shutil.rmtree(work, ignore_errors=True)
    del t0
    return problems


class _Alarm(Exception):
    pass


def _on_alarm(signum, frame):
    raise _Alarm


# -- Ctrl-C: (name, argv, wait-until, expected status, log file to check or None)
SIGNAL_CASES = [
    ("disp", ["disp", "illustration5", "--steps", "100000", "--no-settle"], 4.0, 130, None),
    ("guide", ["guide", "puma560", "--to", "0.3,0.1,0.5,0.3,0.1,0.6,0.4,0.1,0.5",
               "--steps", "99999"], 4.0, 130, None),
    ("control", ["control", "--no-plot", "--log", "{work}/run.jsonl"], "log", 2,
     "run.jsonl"),
    ("sweep", ["sweep", "tolerance", "--samples", "2000000", "--threads", "--workers", "1",
               "--output", "{work}/study", "--quiet", "--no-plots"], 8.0, 130, None),
    ("sim galil", ["sim", "galil", "--json"], 3.0, 0, None),
    ("sim encoders", ["sim", "encoders", "--json"], 3.0, 0, None),
    ("view serve", ["view", "model", "puma560", "--serve", "--no-open"], 4.0, 130, None),
]


def run_signal_case(argv: list[str], wait, status: int, log: str | None) -> list[str]:
    work = Path(tempfile.mkdtemp(prefix="sig-"))
    argv = [a.replace("{work}", str(work)) for a in argv]
    env = {**os.environ, "PYTHONPATH": str(ROOT), "BROWSER": "true"}
    # Ctrl-C's default action in the child even when this campaign runs in the background of
    # a shell (which starts background jobs with SIGINT ignored, and children inherit that)
    proc = subprocess.Popen([sys.executable, "-m", "kinestat.cli.main", *argv], cwd=work,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    problems = []
    try:
        t0 = time.monotonic()
        if wait == "log":
            while time.monotonic() - t0 < 90 and proc.poll() is None:
                p = work / log
                if p.exists() and '"command"' in p.read_text(errors="replace"):
                    break
                time.sleep(0.2)
        else:
            time.sleep(wait)
        if proc.poll() is not None:
            return [f"ended before the signal (exit {proc.returncode})"]
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        return ["did not stop within 60 s of SIGINT"]
    lines = [ln for ln in err.splitlines() if ln.startswith("kinestat:")
             and not ln.startswith("kinestat: compiling")]
    if "Traceback" in err:
        problems.append("traceback printed")
    if proc.returncode != status:
        problems.append(f"exit {proc.returncode}, not {status}: {err.strip().splitlines()[-1:]}")
    if status != 0 and len([ln for ln in lines if "interrupt" in ln or "SIGINT" in ln]) != 1:
        problems.append(f"no single stop line on stderr: {lines[-3:]}")
    if log is not None:
        recs = [json.loads(r) for r in (work / log).read_text().splitlines() if r.strip()]
        kinds = [r.get("type") for r in recs]
        if kinds[-2:] != ["fault", "end"]:
            problems.append(f"cycle log does not end in fault, end: {kinds[-3:]}")
    shutil.rmtree(work, ignore_errors=True)
    return problems


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a sample: the first case of a "
                    "class per command, no Ctrl-C runs")
    ap.add_argument("--no-signals", action="store_true", help="skip the Ctrl-C runs")
    ap.add_argument("--signals-only", action="store_true", help="only the Ctrl-C runs")
    ap.add_argument("--only", default="", help="only commands starting so (e.g. 'fk')")
    ap.add_argument("--alarm", type=float, default=60.0, help="seconds per call")
    args = ap.parse_args()
    os.environ["BROWSER"] = "true"
    signal.signal(signal.SIGALRM, _on_alarm)
    fx = Path(tempfile.mkdtemp(prefix="kinestat-fuzz-"))
    subs = _fixtures(fx)
    tally: collections.Counter = collections.Counter()
    bad: collections.Counter = collections.Counter()
    seen: set[tuple[str, str]] = set()
    for cls, argv, expect, mention in CASES:
        if args.only and not " ".join(argv).startswith(args.only):
            continue
        if args.signals_only or (args.quick and ((cls, argv[0]) in seen or cls not in QUICK)):
            continue
        seen.add((cls, argv[0]))
        tally[cls] += 1
        problems = run_case(argv, expect, mention, subs, args.alarm)
        if problems:
            bad[cls] += 1
            shown = " ".join(repr(a) if " " in a or not a else a for a in argv)
            print(f"VIOLATION [{cls}] kinestat {shown}\n    " + "\n    ".join(problems),
                  flush=True)
    if not (args.quick or args.no_signals):
        for name, argv, wait, status, log in SIGNAL_CASES:
            if args.only and not name.startswith(args.only):
                continue
            tally["sigint"] += 1
            problems = run_signal_case(argv, wait, status, log)
            if problems:
                bad["sigint"] += 1
                print(f"VIOLATION [sigint] kinestat {' '.join(argv)}\n    "
                      + "\n    ".join(problems), flush=True)
    shutil.rmtree(fx, ignore_errors=True)
    print(f"\n{'class':<10} {'cases':>5} {'violations':>10}")
    for cls in sorted(tally):
        print(f"{cls:<10} {tally[cls]:>5} {bad[cls]:>10}")
    print(f"{'total':<10} {sum(tally.values()):>5} {sum(bad.values()):>10}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
