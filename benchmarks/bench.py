"""Side-by-side speed benchmarks: kinestat against its peer libraries, in one run.

Run with ``make bench`` (installs the peers: roboticstoolbox-python, pin, pytorch-kinematics on
CPU torch) or ``.venv/bin/python benchmarks/bench.py [--json] [--quick] [--only TASK...]``.

Every peer works on the same robot: the PUMA 560 (standard DH, metres). Robotics Toolbox builds
it from its own DH model (``DHRobot``) and its C++ ETS form; Pinocchio and pytorch-kinematics
read the URDF that kinestat exports from the same model, so the four describe one arm. Figures
are medians of repeated runs; ratios are peer time / kinestat time (> 1: kinestat is faster).

Tasks: ``fk``, ``jacobian``; ``puma_ik`` (closed-form IK, every branch: kinestat's PUMA 762
against RTB's analytic ``ikine_a`` on its Puma560, the same 6R class); ``numik`` (numerical IK
on the PUMA 560: success rate and time per target on the same random reachable targets from one
fixed start, every answer verified by kinestat's FK); ``platform`` (all-mode forward kinematics
of the special 6-6 prototype, compiled against kinestat's own NumPy reference: no peer solves
it).
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
from kinestat.robots.puma762 import closed_form as P  # noqa: E402
from kinestat.serial.ik import ik  # noqa: E402
from kinestat.spatial.se3 import pose_error  # noqa: E402

RNG = np.random.default_rng(7)
TASKS = ("fk", "jacobian", "puma_ik", "numik", "platform")


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
            import roboticstoolbox as rtb  # lazy: optional peer

            dh = rtb.models.DH.Puma560()
            self.peers["rtb_dh"] = dh
            self.peers["rtb_ets"] = dh.ets()
        except Exception as exc:  # pragma: no cover - peer missing
            self.peers["rtb_error"] = str(exc)
        try:
            import pinocchio as pin  # lazy: optional peer

            pm = pin.buildModelFromXML(self.urdf)
            self.peers["pin"] = (pin, pm, pm.createData(), pm.getFrameId("tool"))
        except Exception as exc:  # pragma: no cover
            self.peers["pin_error"] = str(exc)
        try:
            import pytorch_kinematics as pk  # lazy: optional peer
            import torch  # lazy: optional peer

            torch.set_num_threads(os.cpu_count() or 1)
            chain = pk.build_serial_chain_from_urdf(self.urdf.encode(), "tool")
            self.peers["pk"] = (torch, chain.to(dtype=torch.float64))
        except Exception as exc:  # pragma: no cover
            self.peers["pk_error"] = str(exc)

    def add(self, task: str, impl: str, seconds: float, *, per: str = "call", items: int = 1,
            note: str = "", **extra: float) -> None:
        """One result row; ``extra`` holds task-specific figures (e.g. IK success rates)."""
        self.rows.append({"task": task, "impl": impl, "seconds_per_call": seconds,
                          "items_per_call": items, "per": per,
                          "rate_per_s": items / seconds if seconds > 0 else float("inf"),
                          "note": note, **extra})
        more = "".join(f"  {k}={v:.4f}" for k, v in extra.items())
        print(f"  {task:<28} {impl:<26} {seconds * 1e6:12.2f} µs/call  "
              f"{items / seconds:14.0f} /s{more}  {note}", file=sys.stderr)

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

            def pin_fk_array():  # like for like: the pose as a 4x4 array, as kinestat returns
                return pin_fk().homogeneous

            assert np.allclose(pin_fk().homogeneous, ref, atol=1e-9)
            self.add("fk single", "pinocchio", median_time(pin_fk, number=n), note="SE3 out")
            self.add("fk single", "pinocchio (array)", median_time(pin_fk_array, number=n),
                     note=".homogeneous: 4x4 array out")
        if "rtb_ets" in self.peers:
            ets = self.peers["rtb_ets"]
            # ``eval`` returns the 4x4 array as kinestat does (``fkine`` wraps it in an SE3
            # object, which costs more than the kinematics)
            assert np.allclose(ets.eval(q1), ref, atol=1e-9)
            self.add("fk single", "rtb C++ ETS", median_time(lambda: ets.eval(q1), number=n // 4),
                     note="ets.eval (ndarray)")
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
                assert np.allclose(ets.eval(Qs[:3]), kinestat.fk(m, Qs[:3]), atol=1e-9)
                self.add(task, "rtb C++ ETS",
                         median_time(lambda Qs=Qs, ets=ets: ets.eval(Qs), repeat=3),
                         items=len(Qs), note="ets.eval on N/10")
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

    # -- PUMA closed-form IK, all solutions ---------------------------------------------------
    def puma_ik(self) -> None:
        """kinestat's PUMA 762 closed form (every branch, verified by forward analysis) against
        RTB's analytic ``ikine_a`` on its Puma560: the same 6R class (shoulder offset, spherical
        wrist), different link lengths."""
        note_peer = "solves the PUMA 560 (same 6R class)"
        L = np.radians(P.AXIS_LIMITS_DEG)
        N = 10**4 if self.quick else 10**5
        q = P.from_axis_angles(L[:, 0] + RNG.random((N, 6)) * (L[:, 1] - L[:, 0]))
        T = P.forward(q).pose
        res = P.reverse_pose(T[0])
        assert np.allclose(P.forward(res.solutions).pose, T[0], atol=1e-9)
        n = 500 if self.quick else 5000
        self.add("puma ik all-8 single", "kinestat", median_time(lambda: P.reverse_pose(T[0]),
                                                                 number=n),
                 note="PUMA 762 reverse_pose: 8 branches, verified")
        self.add("puma ik all-8 batch", "kinestat",
                 median_time(lambda: P.reverse_batch_pose(T), repeat=5), items=N,
                 note="reverse_batch_pose, verified")
        self.add("puma ik all-8 batch", "kinestat (no verify)",
                 median_time(lambda: P.reverse_batch_pose(T, verify=False), repeat=5), items=N,
                 note="verify=False")
        if "rtb_dh" in self.peers:
            dh = self.peers["rtb_dh"]
            m = self.model
            q560 = m.lower + RNG.random((50, 6)) * (m.upper - m.lower)
            T560 = kinestat.fk(m, q560)
            configs = [a + b + c for a in "lr" for b in "ud" for c in "nf"]
            for i in range(3):  # the peer's answers reproduce its target
                sol = dh.ikine_a(T560[i], config="lun")
                assert sol.success and np.allclose(kinestat.fk(m, sol.q), T560[i], atol=1e-9)
            k = 10 if self.quick else 50
            one = median_time(lambda: [dh.ikine_a(T560[i], config="lun") for i in range(k)],
                              repeat=3) / k
            self.add("puma ik 1 branch single", "rtb ikine_a", one, note=note_peer)
            self.add("puma ik 1 branch single", "kinestat",
                     self._row("puma ik all-8 single")["seconds_per_call"],
                     note="all 8 branches (same call as above)")
            all8 = median_time(lambda: [dh.ikine_a(T560[i], config=c) for i in range(k // 5)
                                        for c in configs], repeat=3) / (k // 5)
            self.add("puma ik all-8 single", "rtb ikine_a x8", all8, note=note_peer)
            self.add("puma ik all-8 batch", "rtb ikine_a x8 (loop)", all8, items=1,
                     note=note_peer + "; Python loop")

    def _row(self, task: str, impl: str = "kinestat") -> dict:
        return next(r for r in self.rows if r["task"] == task and r["impl"] == impl)

    # -- numerical IK ---------------------------------------------------------------------------
    def numik(self) -> None:
        """Numerical IK on the PUMA 560: the same random reachable targets (random
        configurations within the joint limits, through FK) from one fixed start q = 0, for
        every library. Success is reported by each library and verified here by kinestat's FK:
        position ≤ 1e-6 m, rotation ≤ 1e-6 rad, within the joint limits."""
        m = self.model
        N = 1000 if self.quick else 5000
        qt = m.lower + RNG.random((N, 6)) * (m.upper - m.lower)
        T = kinestat.fk(m, qt)
        q0 = np.zeros(6)
        task = f"numerical ik {N} targets"

        def verified(Q, idx=slice(None)):
            pe, re = pose_error(kinestat.fk(m, Q), T[idx])
            return float(np.mean((pe <= 1e-6) & (re <= 1e-6) & m.within_limits(Q)))

        ik(m, T[:16], q0)  # compile
        for label, kw in (("kinestat", {}), ("kinestat (tol 1e-6)",
                                             {"pos_tol": 1e-6, "rot_tol": 1e-6})):
            out: dict = {}

            def run(kw=kw, out=out):
                out["r"] = ik(m, T, q0, **kw)

            sec = median_time(run, repeat=3)
            r = out["r"]
            tol = "1e-9 x scale m, 1e-9 rad" if not kw else "1e-6 m, 1e-6 rad"
            self.add(task, label, sec, items=N, success=float(r.success.mean()),
                     verified=verified(r.q),
                     note=f"LM + restarts, tol {tol}, {r.iterations.mean():.0f} it/target")
        if "rtb_ets" in self.peers:
            ets = self.peers["rtb_ets"]
            k = min(N, 500 if self.quick else 2000)
            for label, kw in (("rtb C++ ik_LM", {}), ("rtb C++ ik_LM (tol 1e-14)",
                                                      {"tol": 1e-14})):
                sols: list = []

                def rtb_run(kw=kw, sols=sols):
                    sols[:] = [ets.ik_LM(T[i], q0=q0, **kw) for i in range(k)]

                sec = median_time(rtb_run, repeat=3)
                Q = np.array([s.q for s in sols])
                ok = np.array([bool(s.success) for s in sols])
                self.add(task, label, sec, items=k, success=float(ok.mean()),
                         verified=verified(Q, slice(0, k)),
                         note=f"Python loop on {k}; residual E=e'We/2 <= {kw.get('tol', 1e-6):g}")
        if "pk" in self.peers:
            torch, chain = self.peers["pk"]
            import pytorch_kinematics as pk  # lazy: optional peer

            k = min(N, 200 if self.quick else 1000)
            lim = torch.tensor(np.c_[m.lower, m.upper])
            solver = pk.PseudoInverseIK(chain, max_iterations=50, num_retries=10,
                                        joint_limits=lim, early_stopping_any_converged=True,
                                        pos_tolerance=1e-6, rot_tolerance=1e-6)
            goal = pk.Transform3d(matrix=torch.tensor(T[:k]))
            out: dict = {}

            def pk_run(out=out):
                out["sol"] = solver.solve(goal)

            sec = median_time(pk_run, repeat=2)  # the warm-up call is a full solve too
            sol = out["sol"]
            conv = sol.converged.numpy()
            Q = sol.solutions.numpy()[np.arange(k), np.argmax(conv, axis=1)]
            self.add(task, "pytorch_kinematics", sec, items=k,
                     success=float(conv.any(axis=1).mean()),
                     verified=verified(Q, slice(0, k)),
                     note=f"PseudoInverseIK batched on {k}, 10 retries x 50 it, tol 1e-6")


    # -- special 6-6 platform, all assembly modes ----------------------------------------------
    def platform(self) -> None:
        """All-mode forward kinematics of the 2011 prototype platform (no peer library solves
        it): the compiled path against kinestat's NumPy reference ``fk_all``."""
        try:  # lazy: the platform code may be absent in a partial checkout
            from kinestat.io.library import prototype
            from kinestat.parallel.fk import _fk_all_reference, fk_all
        except ImportError as exc:  # pragma: no cover - platform package absent
            print(f"  platform FK not available: {exc}", file=sys.stderr)
            return
        p = prototype()
        N = 2000 if self.quick else 20000
        L = p.free_lengths * (1 + RNG.uniform(-0.1, 0.1, (N, 6)))
        one = L[0]
        fast = fk_all(p, one)
        assert fast.count == _fk_all_reference(p, one).count
        n = 200 if self.quick else 2000
        self.add("platform fk all-mode single", "kinestat",
                 median_time(lambda: fk_all(p, one), number=n),
                 note=f"compiled; {int(fast.count)} modes")
        self.add("platform fk all-mode single", "fk_all (NumPy reference)",
                 median_time(lambda: _fk_all_reference(p, one), number=max(n // 20, 5)))
        self.add("platform fk all-mode batch", "kinestat",
                 median_time(lambda: fk_all(p, L), repeat=5), items=N,
                 note="compiled, 16 slots per set")
        k = N // 10
        self.add("platform fk all-mode batch", "fk_all (NumPy reference)",
                 median_time(lambda: _fk_all_reference(p, L[:k]), repeat=3), items=k,
                 note="on N/10")

    def run(self, only: list[str] | None) -> None:
        for name in TASKS:
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
            if r["task"] == task and not r["impl"].startswith("kinestat"):
                p = r["seconds_per_call"] / r["items_per_call"]
                out.append({"task": task, "peer": r["impl"], "kinestat_per_item_s": k,
                            "peer_per_item_s": p, "ratio": p / k})
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print the results as JSON")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions and sizes")
    ap.add_argument("--only", nargs="*", choices=TASKS, help="tasks to run (default: all)")
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
        if r["impl"].startswith("kinestat"):
            print(f"{r['impl']} {r['task']}: {r['rate_per_s']:,.0f} per second")
    ik_rows = [r for r in b.rows if "success" in r]
    if ik_rows:
        print(f"\n{'numerical IK':<28} {'µs/target':>10} {'success':>8} {'verified':>9}  note")
        for r in ik_rows:
            print(f"{r['impl']:<28} {r['seconds_per_call'] / r['items_per_call'] * 1e6:10.1f} "
                  f"{r['success']:8.2%} {r['verified']:9.2%}  {r['note']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
