"""Side-by-side speed benchmarks: kinestat against its peer libraries, in one run.

Run with ``make bench`` (installs the peers: roboticstoolbox-python, pin, pytorch-kinematics on
CPU torch) or ``.venv/bin/python benchmarks/bench.py [--json] [--quick] [--only TASK...]``.

Every peer works on the same robot: the PUMA 560 (standard DH, metres). Robotics Toolbox builds
it from its own DH model (``DHRobot``) and its C++ ETS form; Pinocchio and pytorch-kinematics
read the URDF that kinestat exports from the same model, so the four describe one arm. Figures
are medians of repeated runs; ratios are peer time / kinestat time (> 1: kinestat is faster).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
import warnings
from collections.abc import Callable

import numpy as np

warnings.filterwarnings("ignore")

import kinestat  # noqa: E402
from kinestat.io.urdf import to_urdf  # noqa: E402

RNG = np.random.default_rng(7)


def median_time(fn: Callable[[], object], *, repeat: int = 7, number: int = 1,
                budget: float = 3.0) -> float:
    """Median seconds per call of ``fn`` over ``repeat`` runs of ``number`` calls each."""
    fn()  # warm-up (compilation, caches)
    times = []
    start = time.perf_counter()
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t0) / number)
        if time.perf_counter() - start > budget and len(times) >= 3:
            break
    return statistics.median(times)


class Bench:
    def __init__(self, quick: bool) -> None:
        self.quick = quick
        self.rows: list[dict] = []
        self.model = kinestat.load("puma560")
        self.urdf = to_urdf(self.model)
        self.peers: dict[str, object] = {}
        self._load_peers()

    # -- peers -------------------------------------------------------------------------------
    def _load_peers(self) -> None:
        try:
            import roboticstoolbox as rtb

            dh = rtb.models.DH.Puma560()
            self.peers["rtb_dh"] = dh
            self.peers["rtb_ets"] = dh.ets()
        except Exception as exc:  # pragma: no cover - peer missing
            self.peers["rtb_error"] = str(exc)
        try:
            import pinocchio as pin

            pm = pin.buildModelFromXML(self.urdf)
            self.peers["pin"] = (pin, pm, pm.createData(), pm.getFrameId("tool"))
        except Exception as exc:  # pragma: no cover
            self.peers["pin_error"] = str(exc)
        try:
            import pytorch_kinematics as pk
            import torch

            torch.set_num_threads(os.cpu_count() or 1)
            chain = pk.build_serial_chain_from_urdf(self.urdf.encode(), "tool")
            self.peers["pk"] = (torch, chain.to(dtype=torch.float64))
        except Exception as exc:  # pragma: no cover
            self.peers["pk_error"] = str(exc)

    def add(self, task: str, impl: str, seconds: float, *, per: str = "call", items: int = 1,
            note: str = "") -> None:
        self.rows.append({"task": task, "impl": impl, "seconds_per_call": seconds,
                          "items_per_call": items, "per": per,
                          "rate_per_s": items / seconds if seconds > 0 else float("inf"),
                          "note": note})
        print(f"  {task:<28} {impl:<22} {seconds * 1e6:12.2f} µs/call  "
              f"{items / seconds:14.0f} /s  {note}", file=sys.stderr)

    # -- forward kinematics -------------------------------------------------------------------
    def fk(self) -> None:
        m = self.model
        q1 = RNG.uniform(-1, 1, 6)
        ref = kinestat.fk(m, q1)
        n = 2000 if self.quick else 20000
        self.add("fk single", "kinestat", median_time(lambda: kinestat.fk(m, q1), number=n))
        if "pin" in self.peers:
            pin, pm, data, fid = self.peers["pin"]

            def pin_fk():
                pin.forwardKinematics(pm, data, q1)
                pin.updateFramePlacement(pm, data, fid)
                return data.oMf[fid]

            assert np.allclose(pin_fk().homogeneous, ref, atol=1e-9)
            self.add("fk single", "pinocchio", median_time(pin_fk, number=n))
        if "rtb_ets" in self.peers:
            ets = self.peers["rtb_ets"]
            assert np.allclose(ets.fkine(q1).A, ref, atol=1e-9)
            self.add("fk single", "rtb C++ ETS", median_time(lambda: ets.fkine(q1), number=n // 4))
        if "rtb_dh" in self.peers:
            dh = self.peers["rtb_dh"]
            self.add("fk single", "rtb DHRobot", median_time(lambda: dh.fkine(q1), number=n // 40))
        if "pk" in self.peers:
            torch, chain = self.peers["pk"]
            t1 = torch.tensor(q1[None])
            assert np.allclose(chain.forward_kinematics(t1).get_matrix().numpy()[0], ref, atol=1e-9)
            self.add("fk single", "pytorch_kinematics",
                     median_time(lambda: chain.forward_kinematics(t1).get_matrix(), number=50))

        for N in ((10**5,) if self.quick else (10**5, 10**6)):
            Q = RNG.uniform(-np.pi, np.pi, (N, 6))
            task = f"fk batch {N:.0e}"
            self.add(task, "kinestat", median_time(lambda Q=Q: kinestat.fk(m, Q), repeat=5),
                     items=N)
            if "rtb_ets" in self.peers:
                ets = self.peers["rtb_ets"]
                Qs = Q[: N // 10]
                self.add(task, "rtb C++ ETS",
                         median_time(lambda Qs=Qs, ets=ets: ets.fkine(Qs), repeat=3),
                         items=len(Qs), note="on N/10")
            if "pin" in self.peers:
                pin, pm, data, fid = self.peers["pin"]
                Qs = Q[: N // 10]

                def pin_loop(Qs=Qs, pin=pin, pm=pm, data=data, fid=fid):
                    for q in Qs:
                        pin.forwardKinematics(pm, data, q)
                        pin.updateFramePlacement(pm, data, fid)

                self.add(task, "pinocchio (loop)", median_time(pin_loop, repeat=3),
                         items=len(Qs), note="Python loop on N/10")
            if "pk" in self.peers:
                torch, chain = self.peers["pk"]
                tq = torch.tensor(Q)
                self.add(task, "pytorch_kinematics",
                         median_time(lambda tq=tq, chain=chain:
                                     chain.forward_kinematics(tq).get_matrix(), repeat=3),
                         items=N)

    # -- Jacobian ----------------------------------------------------------------------------
    def jacobian(self) -> None:
        m = self.model
        q1 = RNG.uniform(-1, 1, 6)
        J = kinestat.jacobian(m, q1)
        n = 2000 if self.quick else 20000
        self.add("jacobian single", "kinestat", median_time(lambda: kinestat.jacobian(m, q1),
                                                            number=n))
        if "pin" in self.peers:
            pin, pm, data, fid = self.peers["pin"]
            jid = pm.getJointId(pm.names[-1])

            def pin_jac():
                return pin.computeJointJacobian(pm, data, q1, jid)

            # Pinocchio's LOCAL joint Jacobian; kinestat's is the spatial twist [w; v_O].
            pin.computeJointJacobians(pm, data, q1)
            Jw = pin.getJointJacobian(pm, data, jid, pin.ReferenceFrame.WORLD)
            assert np.allclose(np.r_[Jw[3:], Jw[:3]], J, atol=1e-9)
            self.add("jacobian single", "pinocchio", median_time(pin_jac, number=n))
        if "rtb_ets" in self.peers:
            ets = self.peers["rtb_ets"]
            self.add("jacobian single", "rtb C++ ETS", median_time(lambda: ets.jacob0(q1),
                                                                  number=n // 4))
        N = 10**5
        Q = RNG.uniform(-np.pi, np.pi, (N, 6))
        self.add("jacobian batch 1e+05", "kinestat",
                 median_time(lambda: kinestat.jacobian(m, Q), repeat=5), items=N)
        if "pin" in self.peers:
            pin, pm, data, fid = self.peers["pin"]
            Qs = Q[: N // 10]

            def pin_loop():
                for q in Qs:
                    pin.computeJointJacobian(pm, data, q, jid)

            self.add("jacobian batch 1e+05", "pinocchio (loop)", median_time(pin_loop, repeat=3),
                     items=len(Qs), note="Python loop on N/10")
        if "pk" in self.peers:
            torch, chain = self.peers["pk"]
            tq = torch.tensor(Q)
            self.add("jacobian batch 1e+05", "pytorch_kinematics",
                     median_time(lambda: chain.jacobian(tq), repeat=3), items=N)

    def run(self, only: list[str] | None) -> None:
        for name in ("fk", "jacobian"):
            if only and name not in only:
                continue
            print(f"[{name}]", file=sys.stderr)
            getattr(self, name)()


def summary(rows: list[dict]) -> list[dict]:
    """kinestat against each peer, per task: ratio of time per item (peer / kinestat)."""
    out = []
    tasks = dict.fromkeys(r["task"] for r in rows)
    for task in tasks:
        ours = [r for r in rows if r["task"] == task and r["impl"] == "kinestat"]
        if not ours:
            continue
        k = ours[0]["seconds_per_call"] / ours[0]["items_per_call"]
        for r in rows:
            if r["task"] == task and r["impl"] != "kinestat":
                p = r["seconds_per_call"] / r["items_per_call"]
                out.append({"task": task, "peer": r["impl"], "kinestat_per_item_s": k,
                            "peer_per_item_s": p, "ratio": p / k})
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print the results as JSON")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions and sizes")
    ap.add_argument("--only", nargs="*", help="tasks to run (fk, jacobian)")
    args = ap.parse_args(argv)
    b = Bench(args.quick)
    b.run(args.only)
    result = {"machine": {"python": platform.python_version(), "cpus": os.cpu_count(),
                          "platform": platform.platform()},
              "rows": b.rows, "vs_peers": summary(b.rows),
              "peer_errors": {k: v for k, v in b.peers.items() if k.endswith("_error")}}
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    print(f"\n{'task':<24} {'kinestat':>14} {'peer':<22} {'peer':>14} {'ratio':>8}")
    for s in result["vs_peers"]:
        fmt = lambda sec: f"{sec * 1e6:10.3f} µs" if sec >= 1e-6 else f"{sec * 1e9:10.1f} ns"  # noqa: E731
        print(f"{s['task']:<24} {fmt(s['kinestat_per_item_s']):>14} {s['peer']:<22} "
              f"{fmt(s['peer_per_item_s']):>14} {s['ratio']:8.2f}")
    for r in b.rows:
        if r["impl"] == "kinestat":
            print(f"kinestat {r['task']}: {r['rate_per_s']:,.0f} per second")
    return 0


if __name__ == "__main__":
    sys.exit(main())
