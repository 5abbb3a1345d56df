"""Bad calls of every ``kinestat`` command: each option given each of a set of bad values.

Usage::

    .venv/bin/python benchmarks/cli_bad_calls.py [COMMAND-PREFIX ...] [--alarm 8]

Walks the command tree (Typer/Click), and for every option that takes a value calls
``kinestat <command> <plausible arguments> <option> <bad value>`` in-process
(:func:`kinestat.cli.main.main`) with each of :data:`BAD` (NaN, infinities, 0, -1, 5000 digits,
an empty string, a non-UTF-8 file, a directory, a missing path...). ``sweep`` calls get an
unreachable ``--scheduler`` so that a valid spec fails fast instead of running a study. A call
passes when it exits 0, or 2 with exactly one ``kinestat: error:`` line; anything else (a
traceback, another status, more lines, longer than ``--alarm`` seconds) is printed. Servers
(``sim galil``, ``sim encoders``) and ``home`` (network) are skipped.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import os
import signal
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

SKIP = {"sim galil", "sim encoders", "home"}


class _Alarm(Exception):
    pass


def _on_alarm(signum, frame):
    raise _Alarm


def _walk(cmd, path):
    if hasattr(cmd, "commands"):
        for name, sub in cmd.commands.items():
            yield from _walk(sub, path + [name])
    else:
        yield path, cmd


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("prefixes", nargs="*", help="only commands starting so (e.g. fk sweep)")
    ap.add_argument("--alarm", type=float, default=8.0, help="seconds per call")
    args = ap.parse_args()
    os.environ["BROWSER"] = "true"  # view: never open a browser
    import typer

    from kinestat.cli.main import app
    from kinestat.cli.main import main as kmain

    tmp = Path(tempfile.mkdtemp())
    (tmp / "bad.txt").write_bytes(b"\xff\xfe\x00garbage\x80")
    (tmp / "empty.toml").write_text("")
    bad = ["nan", "inf", "-inf", "-1", "0", "1e999", "", "abc", "9" * 5000,
           str(tmp / "bad.txt"), str(tmp), "/nonexistent/x", str(tmp / "empty.toml"), "1,2",
           "-0"]
    signal.signal(signal.SIGALRM, _on_alarm)
    tally: collections.Counter = collections.Counter()
    os.chdir(tmp)  # anything a call writes by default lands here
    for path, cmd in _walk(typer.main.get_command(app), []):
        key = " ".join(path)
        if key in SKIP or (args.prefixes and not any(key.startswith(p) for p in args.prefixes)):
            continue
        positional = ["puma560" for p in cmd.params if p.param_type_name == "argument"]
        for p in cmd.params:
            if p.param_type_name != "option" or getattr(p, "is_flag", False) or p.name == "help":
                continue
            for v in bad:
                argv = path + positional + [p.opts[0], v]
                if path[0] == "sweep" and p.opts[0] not in ("--scheduler", "--timeout"):
                    argv += ["--scheduler", "tcp://127.0.0.1:9", "--timeout", "0.5",
                             "--output", str(tmp / "sweep-out")]
                err = io.StringIO()
                signal.setitimer(signal.ITIMER_REAL, args.alarm)
                try:
                    with contextlib.redirect_stdout(io.StringIO()), \
                            contextlib.redirect_stderr(err):
                        code = kmain(argv)
                    lines = err.getvalue().strip().splitlines()
                    one = len(lines) == 1 and lines[0].startswith("kinestat: error:")
                    verdict = "ok" if code == 0 or (code == 2 and one) else (
                        f"status {code}, {len(lines)} stderr lines")
                except _Alarm:
                    verdict = "slow"
                except BaseException as exc:  # noqa: BLE001 - what this probe counts
                    verdict = f"traceback {type(exc).__name__}: {str(exc)[:100]}"
                finally:
                    signal.setitimer(signal.ITIMER_REAL, 0)
                tally["calls"] += 1
                if verdict != "ok":
                    tally[verdict.split(" ")[0]] += 1
                    shown = " ".join(a if len(a) < 40 else a[:20] + "..." for a in argv)
                    print(f"{shown} -> {verdict}: {err.getvalue()[:160]!r}", flush=True)
    print(dict(tally))
    return 1 if set(tally) - {"calls", "slow"} else 0


if __name__ == "__main__":
    sys.exit(main())
