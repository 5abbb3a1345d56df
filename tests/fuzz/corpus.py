"""Fuzzing corpus shared by ``tests/fuzz`` and ``benchmarks/fuzz_campaign.py``.

For each kinestat reader: valid seed inputs (built from the embedded data, so they follow the
formats as they are today), a set of mutators that damage them in the ways the hardening campaign
found harmful (integers with hundreds or thousands of digits, deep nesting, wrong types, binary
bytes, swapped names that close URDF cycles, markup in names, truncation...), and the call that
feeds one input to the reader. The property every reader must keep: whatever the input, the only
exception that escapes is a :class:`~kinestat.errors.KinestatError`.

Mutators take a :class:`random.Random` and the text and return new text (``str``; a file-based
reader writes it with ``surrogateescape``, so the characters U+DC80..U+DCFF become raw,
non-UTF-8 bytes).
"""

from __future__ import annotations

import json
import random
import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path

import numpy as np
import tomli_w

__all__ = ["CLI_READER", "READERS", "Reader", "mutate", "seeds", "NASTY_VALUES", "to_bytes"]

#: Values the campaign substitutes for numbers and strings.
NASTY_VALUES: tuple[str, ...] = (
    "1" + "0" * 20, "1" + "0" * 400, "-" + "9" * 700, "7" * 4301, "9" * 5000,
    "nan", "inf", "-inf", "1e999", "-1e-999", "-0", "0x10", "0b1", "1_000", "true", "false",
    "[]", "{}", "[[]]", '""', '"x"', "abc", "", "[1, 2, 3]", '{a = 1}', '{"a": 1}',
    "1979-05-27T07:32:00Z", "'[/]'", '"[/]"', '"[bold]x[/]"', "null", "NaN", "Infinity",
)
_NUMBER = re.compile(r"-?\d+(?:\.\d*)?(?:[eEdD][-+]?\d+)?")
_QUOTED = re.compile(r'"[^"\n]*"')
_ALPHABET = list("[]{}=\"',\n#<>/&;:.-+eE0123456789 \t\r\\") + [
    "\x00", "\ufeff", "é", "\u202e", "\udc80", "\udcff", "[/]", "<!--", "-->", "]]", "[[",
    "<![CDATA[", "&lt;", "&#0;", "&bogus;",
]


def _nest(rng: random.Random) -> str:
    k = rng.choice([3, 50, 999, 5_000, 100_000])
    return "[" * k + "1" + "]" * k


def _m_number(rng: random.Random, text: str) -> str:
    hits = list(_NUMBER.finditer(text))
    if not hits:
        return text + rng.choice(NASTY_VALUES)
    m = rng.choice(hits)
    new = _nest(rng) if rng.random() < 0.1 else rng.choice(NASTY_VALUES)
    return text[:m.start()] + new + text[m.end():]


def _m_string(rng: random.Random, text: str) -> str:
    hits = list(_QUOTED.finditer(text))
    if not hits:
        return text
    m = rng.choice(hits)
    new = rng.choice(['"[/]"', '"[link=http://example.invalid]x[/link]"', '"' + "x" * 10_000 + '"',
                      '"é\u202e"', "[]", "{}", "1", '""', '"\\u0000"', "true"])
    return text[:m.start()] + new + text[m.end():]


def _m_swap_quoted(rng: random.Random, text: str) -> str:
    """Give one quoted value another's text (in URDF: a link named twice, or a cycle)."""
    hits = list(_QUOTED.finditer(text))
    if len(hits) < 2:
        return text
    a, b = rng.sample(hits, 2)
    return text[:a.start()] + b.group() + text[a.end():]


def _m_delete(rng: random.Random, text: str) -> str:
    if not text:
        return text
    i = rng.randrange(len(text))
    return text[:i] + text[i + rng.randint(1, 40):]


def _m_duplicate(rng: random.Random, text: str) -> str:
    if not text:
        return text
    i = rng.randrange(len(text))
    j = min(len(text), i + rng.randint(1, 200))
    return text[:j] + text[i:j] * rng.randint(1, 3) + text[j:]


def _m_insert(rng: random.Random, text: str) -> str:
    i = rng.randint(0, len(text))
    ins = "".join(rng.choice(_ALPHABET) for _ in range(rng.randint(1, 6)))
    return text[:i] + ins + text[i:]


def _m_nest(rng: random.Random, text: str) -> str:
    i = rng.randint(0, len(text))
    k = rng.choice([10, 1_000, 100_000])
    opener = rng.choice(["[", "{", "<a>", "x = ["])
    closer = {"[": "]", "{": "}", "<a>": "</a>", "x = [": "]"}[opener]
    return text[:i] + opener * k + closer * k + text[i:]


def _m_truncate(rng: random.Random, text: str) -> str:
    return text[:rng.randint(0, len(text))]


def _m_lines(rng: random.Random, text: str) -> str:
    lines = text.split("\n")
    if len(lines) < 2:
        return text
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    if rng.random() < 0.5:
        lines[i], lines[j] = lines[j], lines[i]
    else:
        lines.insert(i, lines[j])
    return "\n".join(lines)


def _m_binary(rng: random.Random, text: str) -> str:
    i = rng.randint(0, len(text))
    junk = "".join(chr(0xDC80 + rng.randrange(128)) for _ in range(rng.randint(1, 8)))
    return text[:i] + junk + text[i:]


MUTATORS: tuple[Callable[[random.Random, str], str], ...] = (
    _m_number, _m_number, _m_number, _m_string, _m_swap_quoted, _m_delete, _m_duplicate,
    _m_insert, _m_insert, _m_nest, _m_truncate, _m_lines, _m_binary,
)


def mutate(rng: random.Random, text: str, rounds: int | None = None) -> str:
    """``text`` after 1-4 (or ``rounds``) random mutations."""
    for _ in range(rounds if rounds is not None else rng.randint(1, 4)):
        text = rng.choice(MUTATORS)(rng, text)
    return text


def to_bytes(text: str) -> bytes:
    """UTF-8, U+DC80..U+DCFF as the raw bytes they stand for, other lone surrogates as their
    (invalid) UTF-8 forms."""
    try:
        return text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:
        return text.encode("utf-8", "surrogatepass")


# ---------------------------------------------------------------------------------- seeds


def _data(*parts: str) -> str:
    return resources.files("kinestat.data").joinpath(*parts).read_text(encoding="utf-8")


def _model_seeds() -> list[str]:
    names = ("puma560", "puma762", "nadkarni-config1", "nadkarni-config2")
    return [_data("models", f"{n}.toml") for n in names]


def _platform_seeds() -> list[str]:
    from kinestat.io import dumps_platform, prototype
    from kinestat.parallel.platform import Platform

    proto = prototype()
    explicit = Platform(base_points=proto.base_points, top_points=proto.top_points,
                        stiffness=proto.stiffness, free_lengths=proto.free_lengths,
                        home_pose=proto.home_pose, name="explicit")
    return [_data("platforms", "prototype-2011.toml"), dumps_platform(explicit)]


_AXES_DOC = {
    "name": "arm", "length_unit": "mm", "tol": 1e-9,
    "axes": [
        {"name": "1", "point": [0.0, 0.0, 0.0], "direction": [0.0, 0.0, 1.0]},
        {"name": "2", "point": [0.0, 0.0, 660.4], "direction": [0.0, 1.0, 0.0]},
        {"name": "3", "type": "prismatic", "point": [431.8, 0.0, 660.4],
         "direction": [1.0, 0.0, 0.0]},
        {"name": "4", "type": "screw", "pitch": 2.5, "plucker": [0.0, 0.0, 1.0, 1.0, 0.0, 0.0]},
    ],
    "tool": [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 100.0], [0, 0, 0, 1.0]],
}
_POSE = [[0.0, -1.0, 0.0, 0.45], [1.0, 0.0, 0.0, 0.15], [0.0, 0.0, 1.0, 0.43], [0, 0, 0, 1.0]]


def _urdf_seeds() -> list[str]:
    from kinestat.io import load, to_urdf

    branch = (
        '<robot name="tree"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>'
        '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>'
        '<origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 1 0"/>'
        '<limit lower="-1" upper="1" effort="0" velocity="0"/></joint>'
        '<joint name="j2" type="prismatic"><parent link="b"/><child link="c"/>'
        '<axis xyz="1 0 0"/><limit lower="0" upper="0.5"/></joint>'
        '<joint name="j3" type="fixed"><parent link="c"/><child link="d"/></joint></robot>'
    )
    return [to_urdf(load("puma560")), to_urdf(load("puma762"), scale=1e-3), branch]


def _deck_seeds() -> list[str]:
    folder = resources.files("kinestat.data").joinpath("decks")
    return sorted(p.read_text(encoding="ascii") for p in folder.iterdir()
                  if p.name.endswith(".dat"))


#: Fast, side-effect-free command lines (no files written, no simulator started); an input is
#: a command line split on blanks.
_CLI_SEEDS: tuple[str, ...] = (
    "fk puma762 --q-deg 10,20,30,40,50,60",
    "fk puma560 --q 0.1,0.2,0.3,0.4,0.5,0.6 --json",
    "ik puma762 --pose 1,0,0,700,0,1,0,200,0,0,1,600,0,0,0,1 --json",
    "screw --pose1 1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1 --pose2 0,-1,0,1,1,0,0,2,0,0,1,3,0,0,0,1",
    "platform info",
    "platform ik --pose 1,0,0,30,0,1,0,51.96,0,0,1,60,0,0,0,1 --json",
    "platform statics --pose 1,0,0,30,0,1,0,51.96,0,0,1,60,0,0,0,1 --wrench 0,0,-10,0,0,0",
    "control --forse 4",
    "disp illustration1 --json",
)


#: Galil DMC command lines the simulator's handler answers (Vibhute App. D.4, D.5, D.9 and the
#: client's stop proof).
_GALIL_SEEDS: tuple[str, ...] = (
    "MG @IN[3]", "MG @AN[2]", "MG _BGA,_TPB,_MOC", "PA 1000,2000,-3000,0,0,5", "PR ,,100",
    "SP 8000,11511,8964,3194,1469.24,1496", "AC 8000,11511,8964,3194,3194,1496", "DC 1,2",
    "JG 1000,-500", "FI", "FI AB", "BG", "BG A", "ST", "ST AC", "TP", "TP A", "TC1", "TC", "MO",
    "SH", "DP 0,103597,80672,0,0,0", "AF 0,0,0,0,0,0", "OP1", "HOMED=1", "MG HOMED",
    "MG 4711,_BGA,_BGB,_BGC,_BGD,_BGE,_BGF",
)


def _calibration_seeds() -> list[str]:
    return [_data("calibrations", "thesis-2011.toml")]


@cache
def seeds(reader: str) -> tuple[str, ...]:
    """The valid seed inputs of ``reader`` (a key of :data:`READERS`)."""
    if reader == "model_toml":
        return tuple(_model_seeds())
    if reader in ("platform_toml", "control_platform"):
        return tuple(_platform_seeds())
    if reader == "axes_toml":
        return (tomli_w.dumps(_AXES_DOC),)
    if reader == "axes_json":
        return (json.dumps(_AXES_DOC, indent=1),)
    if reader == "pose_numbers":
        rows = np.asarray(_POSE)
        return ("\n".join(" ".join(f"{v:.6g}" for v in r) for r in rows) + "\n",
                "# top rows\n" + "\n".join(", ".join(f"{v:.6g}" for v in r) for r in rows[:3]))
    if reader == "pose_json":
        return (json.dumps({"pose": _POSE}), json.dumps([_POSE, _POSE]),
                json.dumps(sum(_POSE, [])))
    if reader == "pose_toml":
        return (tomli_w.dumps({"pose": _POSE}),)
    if reader == "urdf":
        return tuple(_urdf_seeds())
    if reader == "disp_deck":
        return tuple(_deck_seeds())
    if reader == "text":
        return (*_model_seeds()[:1], _deck_seeds()[0], "plain text\n")
    if reader == "cli":
        return _CLI_SEEDS
    if reader in ("calibration_toml", "control_calibration"):
        return tuple(_calibration_seeds())
    if reader == "galil_handler":
        return _GALIL_SEEDS
    raise KeyError(reader)


# -------------------------------------------------------------------------------- readers


def _write(workdir: Path, name: str, text: str) -> Path:
    p = workdir / name
    p.write_bytes(to_bytes(text))
    return p


def _model(text: str, workdir: Path):
    from kinestat.io import loads_model, read_model

    if "\udc80" <= max(text, default="a") and any("\udc80" <= c <= "\udcff" for c in text):
        return read_model(_write(workdir, "model.toml", text))
    return loads_model(text, source="fuzz.toml")


def _platform(text: str, workdir: Path):
    from kinestat.io import read_platform

    return read_platform(_write(workdir, "platform.toml", text))


def _axes(suffix: str):
    def call(text: str, workdir: Path):
        from kinestat.io import read_axes_file

        return read_axes_file(_write(workdir, f"axes{suffix}", text))
    return call


def _pose(suffix: str, allow_batch: bool):
    def call(text: str, workdir: Path):
        from kinestat.io import read_pose_file

        return read_pose_file(_write(workdir, f"pose{suffix}", text), allow_batch=allow_batch)
    return call


def _urdf(text: str, workdir: Path):
    from kinestat.io import read_urdf

    return read_urdf(_write(workdir, "robot.urdf", text), scale=1000.0, length_unit="mm")


def _deck(text: str, workdir: Path):
    from kinestat.io import read_deck  # the public name (the module may become a package)

    return read_deck(to_bytes(text))


def _text(text: str, workdir: Path):
    from kinestat.io.textfile import read_text_file

    return read_text_file(_write(workdir, "any.txt", text), "text file")


def _cli(text: str, workdir: Path):
    """Run one command line in-process; a traceback (an exception out of ``main``) or an error
    that is not exactly one ``kinestat: error:`` line fails."""
    import contextlib
    import io

    from kinestat.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([a for a in text.split(" ") if a])
    lines = err.getvalue().splitlines()
    if code == 2 and lines and lines[0].startswith("kinestat: error:") and len(lines) != 1:
        raise AssertionError(f"a {len(lines)}-line error: {err.getvalue()[:200]!r}")
    return code


def _calibration(text: str, workdir: Path):
    from kinestat.io.calibration_toml import loads_calibration, read_calibration

    if any("\udc80" <= c <= "\udcff" for c in text):
        return read_calibration(_write(workdir, "calibration.toml", text))
    return loads_calibration(text, source="fuzz.toml")


def _control_calibration(text: str, workdir: Path):
    """``kinestat control --calibration FILE``: the file read and the controller's model built
    from it (:mod:`kinestat.app.calibrations`)."""
    from kinestat.app.calibrations import calibrated_model, resolve_calibration, resolve_platform

    platform = resolve_platform(None)
    cal = resolve_calibration(str(_write(workdir, "control-cal.toml", text)), platform)
    return calibrated_model(platform, cal)


def _control_platform(text: str, workdir: Path):
    """``kinestat control --platform FILE``: the platform read and the controller's model
    built on it with the thesis's and the nominal calibrations."""
    from kinestat.app.calibrations import calibrated_model, resolve_calibration, resolve_platform

    platform = resolve_platform(_write(workdir, "control-platform.toml", text))
    return [calibrated_model(platform, resolve_calibration(c, platform))
            for c in ("thesis", "nominal")]


def _galil_handler(text: str, workdir: Path):
    """One command line to the simulated DMC's interpreter: it must answer (``:``, data then
    ``:``, or ``?``), never raise — an exception would end the server's connection thread."""
    from kinestat.sim.dmc import DmcSimulator, SimClock

    line = text.encode("ascii", "replace").decode("ascii")  # what the server decodes
    reply = DmcSimulator(clock=SimClock(step_per_command=0.01)).handle(line)
    if not (isinstance(reply, str) and reply.endswith((":", "?"))):
        raise AssertionError(f"no DMC reply to {line[:60]!r}: {reply!r}")
    return reply


@dataclass(frozen=True)
class Reader:
    """One reader under test: ``call(text, workdir)`` feeds it one input."""

    name: str
    call: Callable[[str, Path], object]


READERS: dict[str, Reader] = {r.name: r for r in (
    Reader("model_toml", _model),
    Reader("platform_toml", _platform),
    Reader("axes_toml", _axes(".toml")),
    Reader("axes_json", _axes(".json")),
    Reader("pose_numbers", _pose(".txt", False)),
    Reader("pose_json", _pose(".json", True)),
    Reader("pose_toml", _pose(".toml", False)),
    Reader("urdf", _urdf),
    Reader("disp_deck", _deck),
    Reader("text", _text),
    Reader("calibration_toml", _calibration),
    Reader("control_calibration", _control_calibration),
    Reader("control_platform", _control_platform),
    Reader("galil_handler", _galil_handler),
)}

#: The command line, fuzzed by the campaign only (``--readers cli``): slower than the readers.
CLI_READER = Reader("cli", _cli)
