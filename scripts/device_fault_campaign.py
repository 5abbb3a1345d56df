"""Seeded fault-injection campaign on the hardware path of `kinestat control` (the press task)
and `kinestat home`, against the simulated DMC and encoder box.

Each case runs the real Galil client through a damaging proxy (tests/_fault_injector.py) or
the real encoder reader over a damaging wrapper, or sends SIGINT/SIGTERM at a random moment,
and checks the safety contract:

* ``stopped``: a fault (or signal) that reached the client ends with ``ST`` received by the
  simulated DMC after it (its command record);
* ``log``: every line of the log is JSON, the first record ``start``, the last ``end`` whose
  report names why it stopped (a ``fault`` record before it when a fault fired);
* ``limits``: every ``PA`` sent lies inside the arm's joint limits and within 30° of the
  previous one (the press), every ``PR`` of homing within its coarse-move bound;
* ``good``: good-but-odd input (25 replies in a row split byte by byte, or with extra blanks)
  runs exactly as without it (no fault record).

Usage (one campaign at a time; a quick run takes about a minute):

    PYTHONPATH=$PWD .venv/bin/python scripts/device_fault_campaign.py --quick --seed 1
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import random
import signal
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from kinestat.app.homing_run import run_home  # noqa: E402
from kinestat.app.signals import stop_on_signals  # noqa: E402
from kinestat.app.sim_cell import SimCheckedReader, SimHarness, start_counts  # noqa: E402
from kinestat.control.envelope import sent_command_guard  # noqa: E402
from kinestat.control.log import CycleLog  # noqa: E402
from kinestat.control.loop import run  # noqa: E402
from kinestat.devices.cell_io import DeviceIO, MotionProfile  # noqa: E402
from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX, GalilClient  # noqa: E402
from kinestat.hardware.puma762_axes import AXIS_DEG_PER_COUNT  # noqa: E402
from kinestat.sim.dmc import DmcSimulator, SimClock  # noqa: E402
from kinestat.sim.galil_server import GalilSimServer  # noqa: E402
from tests._fault_injector import (  # noqa: E402
    GOOD_WIRE,
    STREAM_FAULTS,
    WIRE_FAULTS,
    FaultProxy,
    corrupt_stream,
)
from tests.control.conftest import scenario  # noqa: E402

FAST = MotionProfile(speed=tuple(20 * np.asarray(THESIS_SPEED_MAX)),
                     accel=tuple(400 * np.asarray(THESIS_ACCEL)))
COUPLED = -11200.0 / 23962.0
SIGNALS = ("SIGINT", "SIGTERM")
TIMEOUT = 0.4  # the client's reply timeout in the campaign (s); 'late' holds a reply longer
MAX_COARSE = 60000.0
GOOD_SPAN = 25  # good-but-odd input: the replies to this many commands in a row


def read_log_lines(path: Path) -> tuple[list[dict], list[str]]:
    """The records of a JSON-lines log, and what is wrong with it."""
    recs, bad = [], []
    text = path.read_text() if path.exists() else ""
    for k, line in enumerate(text.splitlines(), 1):
        try:
            recs.append(json.loads(line))
        except json.JSONDecodeError:
            bad.append(f"line {k} is not JSON")
    if not text.endswith("\n"):
        bad.append("the log does not end with a complete line")
    return recs, bad


def check_log(recs: list[dict], bad: list[str], fired: bool) -> list[str]:
    out = list(bad)
    if not recs or recs[0].get("type") != "start":
        out.append("the first record is not 'start'")
    if not recs or recs[-1].get("type") != "end":
        return [*out, "the last record is not 'end'"]
    rep = recs[-1].get("report", {})
    reason = rep.get("stop_reason") or rep.get("reason") or ""
    if not reason:
        out.append("the end record does not say why the run ended")
    if fired and not any(r.get("type") == "fault" for r in recs):
        out.append("a fault fired but the log has no 'fault' record")
    return out


def check_pa(commands: list[str], limits_deg: np.ndarray, start) -> list[str]:
    lo, hi = np.asarray(limits_deg).T
    prev = np.asarray(start, dtype=float)
    out = []
    for c in commands:
        if c.startswith("PA"):
            counts = np.array([float(v) for v in c[2:].split(",")])
            deg = counts * AXIS_DEG_PER_COUNT
            if not np.all((deg >= lo) & (deg <= hi)):
                out.append(f"{c} outside the joint limits")
            if np.max(np.abs(counts - prev) * AXIS_DEG_PER_COUNT) > 30.0:
                out.append(f"{c} more than 30° from the previous command")
            prev = counts
    return out


def stop_after(commands: list[str], n: int | None) -> list[str]:
    if n is None:
        return []
    return [] if "ST" in commands[n:] else [f"no ST after the fault (command {n})"]


# ----------------------------------------------------------------------------- the press


def press_case(kind: str, at: float, seed: int, tmp: Path) -> dict:
    """One run of the press over the simulated cell with fault ``kind`` at ``at`` (a command
    number, a stream chunk number, or seconds for a signal)."""
    scn = scenario(coupling=COUPLED)
    cfg = scn.config()
    path = tmp / f"press-{kind}-{seed}.jsonl"
    c0 = start_counts(cfg)
    mark: dict = {}
    with SimHarness(scn.cell, scn.sensor, start_counts=c0, record=True) as h, \
            FaultProxy(h.server.port, seed=seed, delay=2.5 * TIMEOUT) as proxy:
        client = GalilClient("127.0.0.1", proxy.port, timeout=TIMEOUT).connect()
        raw_reader = h.reader()
        reader = SimCheckedReader(raw_reader, h.emitter)
        io = DeviceIO(client, reader, truth=h.truth, settle=2.5 / h.emitter.rate_hz,
                      guard=sent_command_guard(cfg.envelope, cfg.model), profile=FAST)
        stream = None
        if kind in WIRE_FAULTS + GOOD_WIRE:
            proxy.arm(kind, int(at), span=GOOD_SPAN)
        elif kind in STREAM_FAULTS:
            stream = corrupt_stream(raw_reader, kind, int(at), seed=seed,
                                    stall=1.5 * raw_reader.stale_after)
            stream.on_fire = lambda: mark.setdefault("n", len(h.controller.commands))
        timer = _signal_timer(kind, at, h.controller, mark)
        t0 = time.monotonic()
        escaped = None
        try:
            with stop_on_signals(), CycleLog(path) as log:
                if timer:
                    timer.start()
                converged = run(cfg, io, log).converged
        except (Exception, KeyboardInterrupt) as exc:  # a violation: recorded, not hidden
            escaped, converged = f"run() raised {type(exc).__name__}: {exc}", False
        if timer:
            timer.cancel()
        client.close()
        commands = list(h.controller.commands)
    if proxy.fired_index is not None:
        mark.setdefault("n", proxy.fired_index)
    fired = "n" in mark
    out = _verdict(kind, at, seed, fired, mark.get("n"), commands, path, converged,
                   check_pa(commands, scn.model.limits_deg, c0), time.monotonic() - t0)
    if escaped:
        out["violations"].insert(0, escaped)
    return out


def press_with(setup, tmp: Path):
    """One clean press run with ``setup(harness, proxy)`` called before it starts: (report,
    log records). For combined faults in the tests."""
    scn = scenario(coupling=COUPLED)
    cfg = scn.config()
    path = tmp / "press-with.jsonl"
    with SimHarness(scn.cell, scn.sensor, start_counts=start_counts(cfg), record=True) as h, \
            FaultProxy(h.server.port) as proxy:
        client = GalilClient("127.0.0.1", proxy.port, timeout=TIMEOUT).connect()
        io = DeviceIO(client, SimCheckedReader(h.reader(), h.emitter), truth=h.truth,
                      settle=2.5 / h.emitter.rate_hz, profile=FAST,
                      guard=sent_command_guard(cfg.envelope, cfg.model))
        setup(h, proxy)
        with CycleLog(path) as log:
            rep = run(cfg, io, log)
        client.close()
    return rep, read_log_lines(path)[0]


def _signal_timer(kind: str, at: float, ctrl, mark: dict) -> threading.Timer | None:
    if kind not in SIGNALS:
        return None
    sig = getattr(signal, kind)

    def fire():
        mark["n"] = len(ctrl.commands)
        os.kill(os.getpid(), sig)

    return threading.Timer(float(at), fire)


def _verdict(kind, at, seed, fired, n, commands, path, converged, pa, dt) -> dict:
    recs, bad = read_log_lines(path)
    good = kind in GOOD_WIRE
    faulted = any(r.get("type") == "fault" for r in recs)
    v: list[str] = []
    if good:
        if faulted:
            v.append("good input refused: " + next(r.get("reason", "") for r in recs
                                                  if r.get("type") == "fault"))
        v += check_log(recs, bad, False)
    else:
        v += check_log(recs, bad, fired and faulted)
        if fired and not faulted and kind not in STREAM_FAULTS:
            v.append("a fault reached the client but the run went on as if nothing happened")
        if faulted:
            v += stop_after(commands, n if fired else 0)
    v += pa
    end = recs[-1].get("report", {}) if recs else {}
    return {"kind": kind, "at": at, "seed": seed, "fired": fired, "faulted": faulted,
            "converged": bool(converged), "reason": str(end.get("stop_reason", "")),
            "seconds": round(dt, 2), "violations": v}


# ----------------------------------------------------------------------------- homing


def home_case(kind: str, at: float, seed: int, tmp: Path) -> dict:
    path = tmp / f"home-{kind}-{seed}.jsonl"
    sim = DmcSimulator.unknown_start(seed, clock=SimClock(step_per_command=0.05), record=True)
    mark: dict = {}
    with GalilSimServer(controller=sim) as srv, \
            FaultProxy(srv.port, seed=seed, delay=2.5 * TIMEOUT) as proxy:
        if kind in WIRE_FAULTS + GOOD_WIRE:
            proxy.arm(kind, int(at), span=GOOD_SPAN)
        timer = _signal_timer(kind, at, sim, mark)
        t0 = time.monotonic()
        escaped = None
        try:
            with stop_on_signals():
                if timer:
                    timer.start()
                homed = run_home("127.0.0.1", proxy.port, path, samples=2,
                                 timeout=TIMEOUT).homed
        except (Exception, KeyboardInterrupt) as exc:  # a violation: recorded, not hidden
            escaped, homed = f"run_home() raised {type(exc).__name__}: {exc}", False
        if timer:
            timer.cancel()
        commands = list(sim.commands)
    if proxy.fired_index is not None:
        mark.setdefault("n", proxy.fired_index)
    pr = [f"{c} beyond the coarse bound" for c in commands if c.startswith("PR")
          and max(abs(float(x)) for x in c[2:].split(",")) > MAX_COARSE]
    out = _verdict(kind, at, seed, "n" in mark, mark.get("n"), commands, path, homed, pr,
                   time.monotonic() - t0)
    if escaped:
        out["violations"].insert(0, escaped)
    if out["faulted"] and "MO" not in commands[mark.get("n") or 0:]:
        out["violations"].append("homing fault without MO after the stop")
    return out


# ----------------------------------------------------------------------------- campaign


def baseline(tmp: Path) -> dict:
    """Commands, stream chunks and seconds of a clean press run and a clean homing."""
    scn = scenario(coupling=COUPLED)
    cfg = scn.config()
    with SimHarness(scn.cell, scn.sensor, start_counts=start_counts(cfg), record=True) as h:
        raw = h.reader()
        chunks = [0]
        real = raw._read_chunk

        def counting(*, wait):
            data = real(wait=wait)
            chunks[0] += b"\n" in data
            return data

        raw._read_chunk = counting
        io = DeviceIO(h.client(TIMEOUT), SimCheckedReader(raw, h.emitter), truth=h.truth,
                      settle=2.5 / h.emitter.rate_hz, profile=FAST,
                      guard=sent_command_guard(cfg.envelope, cfg.model))
        t0 = time.monotonic()
        with CycleLog(tmp / "base.jsonl") as log:
            rep = run(cfg, io, log)
        press = {"commands": len(h.controller.commands), "chunks": chunks[0],
                 "seconds": time.monotonic() - t0, "converged": rep.converged}
    sim = DmcSimulator.unknown_start(0, clock=SimClock(step_per_command=0.05), record=True)
    with GalilSimServer(controller=sim) as srv:
        t0 = time.monotonic()
        hrep = run_home("127.0.0.1", srv.port, tmp / "home-base.jsonl", samples=2,
                        timeout=TIMEOUT)
        home = {"commands": len(sim.commands), "seconds": time.monotonic() - t0,
                "homed": hrep.homed}
    return {"press": press, "home": home}


def plan(base: dict, per_kind: int, rng: random.Random) -> list[tuple[str, str, float, int]]:
    cases = []
    for target in ("press", "home"):
        b = base[target]
        kinds = list(WIRE_FAULTS + GOOD_WIRE + SIGNALS)
        if target == "press":
            kinds += STREAM_FAULTS
        for kind in kinds:
            for _ in range(per_kind):
                if kind in SIGNALS:
                    at: float = round(rng.uniform(0.0, b["seconds"]), 3)
                elif kind in STREAM_FAULTS:
                    at = rng.randint(1, max(1, b["chunks"]))
                else:
                    at = rng.randint(1, b["commands"])
                cases.append((target, kind, at, rng.randrange(1 << 30)))
    return cases


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="2 cases per fault class")
    ap.add_argument("--per-kind", type=int, default=None, help="cases per fault class")
    ap.add_argument("--only", default=None, help="comma-separated fault kinds to run")
    ap.add_argument("--target", choices=("press", "home", "both"), default="both")
    ap.add_argument("--out", type=Path, default=None, help="write the cases as JSON lines")
    a = ap.parse_args(argv)
    per_kind = a.per_kind or (2 if a.quick else 6)
    rng = random.Random(a.seed)
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        base = baseline(tmp)
        print(json.dumps({"baseline": base}), flush=True)
        only = set(a.only.split(",")) if a.only else None
        results = []
        for target, kind, at, seed in plan(base, per_kind, rng):
            if (only and kind not in only) or a.target not in ("both", target):
                continue
            fn = press_case if target == "press" else home_case
            r = {"target": target, **fn(kind, at, seed, tmp)}
            results.append(r)
            print(json.dumps(r), flush=True)
    summary: dict = collections.defaultdict(lambda: [0, 0])
    for r in results:
        s = summary[f"{r['target']}:{r['kind']}"]
        s[0] += 1
        s[1] += bool(r["violations"])
    print(json.dumps({"cases": len(results), "violating": sum(bool(r["violations"])
                                                             for r in results),
                      "per_kind": {k: {"cases": c, "violating": v}
                                   for k, (c, v) in sorted(summary.items())}}))
    if a.out:
        a.out.write_text("".join(json.dumps(r) + "\n" for r in results))
    return 1 if any(r["violations"] for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
