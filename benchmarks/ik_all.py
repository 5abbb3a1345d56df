"""All-solutions IK benchmark: kinestat.ik_all against ssik, EAIK, ik-geo and RTB ``ikine_a``.

Run ``.venv/bin/python benchmarks/ik_all.py [--n 10000] [--single 200] [--rounds 5]
[--arms ur5,iiwa-lock3,...] [--json]``.

Arms (the same random configurations, uniform in [-π, π]^6, fixed seed): UR5 (three parallel
axes), PUMA 560 (spherical wrist, embedded), PUMA 762 (embedded, Crane–Duffy frames), a Kinova
Jaco2-type 6R with a 60° wrist (non-Pieper), random general 6Rs (``random1``-``random3``: the
Raghavan–Roth eigenvalue method), three spherical-wrist arms with an offset shoulder (KUKA KR16-2
from rtb-data's URDF, KUKA KR5 and ABB IRB140 from the Robotics Toolbox's DH models; KUKA
KR120 R2500 pro and KR210 L150 from rtb-data's URDFs, held out of the solvers' development) and
the Stanford arm (RRP: the decoupled solver; its prismatic joint drawn within its limits, no peer
takes prismatic joints) and two random DH 6Rs whose axes 2-3-4 (``middle2-1``) or 3-4-5
(``middle3-1``) meet (the middle-wrist closed form). For every solver and arm:
single-call time per pose (one pose per call, median over ``--single`` poses), batched poses/s
(kinestat: one call on ``--n`` poses, the fastest of ``--repeat`` calls; peers have no batch
call, so their figure is 1/single),
each with the CPU time of this process per pose beside it (``cpu µs``: all threads; robust to
other jobs on a shared machine, where wall time is not),
completeness (the generating configuration is among the returned solutions, wrapped distance
< 1e-6), the mean number of solutions (kinestat: over ``--n`` poses; peers: over the
``--single`` poses), the worst pose residual of the returned solutions, every one recomputed
with kinestat's FK, and, per peer on the ``--single`` poses, the fraction of poses where its
number of distinct verified solutions (residual < 1e-6) equals kinestat's and the number of its
verified solutions kinestat lacks. ``n/a`` marks a solver that does not apply. The ik-geo
adapter (product-of-exponentials vectors from kinestat's home axes) is validated only for the
three-parallel class; its zero completeness elsewhere is an adapter/convention mismatch, not a
finding about ik-geo.

Single-call figures of one process can sit 1.3-1.5x high when the host slows this virtual CPU
(see docs/ik-all.md, "Performance"); ``benchmarks/ik_all_processes.py`` gives their
distribution over many processes beside a LAPACK probe that shows the machine's state.

7-joint arms with one joint locked (``ARMS7``: ``<arm>-lock<J>``, J numbered from 1 as in
``kinestat ik --lock J``; the Panda and the xArm7 from example-robot-data, the KUKA iiwa 14
R820 from rtb-data): one locked value per arm drawn within the joint's limits, the other joints
uniform in [-π, π]; kinestat's ``ik_all(model, T, locked={j: value})`` beside EAIK's
``HPRobot(H, P, fixed_axes=[(j, value)]).IK`` and beside kinestat on the folded 6-joint chain
(``kinestat-6R``: the same geometry without the locking step). Single calls run in
``--rounds`` interleaved rounds (each solver in turn over the ``--single`` poses; the fastest
round's median is reported); the EAIK columns count the poses where its verified solutions
number as many as kinestat's and where every solution it returns reproduces the pose.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
import warnings

import numpy as np

warnings.filterwarnings("ignore")
_ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, os.path.join(_ROOT, "tests", "serial", "analytic"))
sys.path.insert(0, _ROOT)  # this checkout's kinestat, not an installed one

from arms import arm  # noqa: E402  (test arms, public constructors)

import kinestat  # noqa: E402
from kinestat.serial.analytic import ik_all  # noqa: E402
from kinestat.serial.analytic.geometry import home_axes, meet, parallel  # noqa: E402
from kinestat.serial.analytic.locked import fold  # noqa: E402

PI = math.pi
ARMS = ("ur5", "puma560", "puma762", "jaco6", "random1", "kr16", "kr5", "irb140", "stanford",
        "random2", "random3", "middle2-1", "middle3-1", "ur10", "ur3", "z1", "kinova-j2s6s200",
        "kr120", "kr210")
#: real 6-joint arms from example-robot-data's URDFs (tests/urdf_arms.py), held out of the
#: solvers' development
URDF6 = ("ur10", "ur3", "z1", "kinova-j2s6s200")
ARMS7 = ("panda-lock7", "panda-lock3", "iiwa-lock3", "xarm7-lock3")


def _wrapdist(a, b):
    return np.max(np.abs(np.mod(a - b + PI, 2 * PI) - PI), axis=-1)


def _score(model, q_true, sols_per_pose):
    """Completeness, mean count and worst residual (pos, rot) of lists of solutions."""
    found, counts, worst = 0, [], 0.0
    for q, sols in zip(q_true, sols_per_pose, strict=True):
        sols = np.asarray(sols, dtype=float).reshape(-1, len(q))
        counts.append(len(sols))
        if len(sols):
            found += bool(np.min(_wrapdist(sols, q)) < 1e-6)
            F = kinestat.fk(model, sols)
            T = kinestat.fk(model, q)
            res = np.maximum(np.linalg.norm(F[:, :3, 3] - T[:3, 3], axis=-1),
                             np.linalg.norm(F[:, :3, :3] - T[:3, :3], axis=(-2, -1)))
            worst = max(worst, float(res.max()))
    return found / len(q_true), float(np.mean(counts)), worst


def _agreement(mine, sols_per_pose):
    """Fraction of poses where the peer's distinct solutions (de-duplicated) number as many as
    kinestat's, and the number of peer solutions kinestat does not have."""
    same, extra = 0, 0
    for m, sols in zip(mine, sols_per_pose, strict=True):
        distinct: list[np.ndarray] = []
        for s in np.asarray(sols, dtype=float).reshape(-1, m.shape[-1]):
            if all(_wrapdist(s, d) > 1e-6 for d in distinct):
                distinct.append(s)
        same += len(distinct) == len(m)
        extra += sum(1 for s in distinct if len(m) == 0 or np.min(_wrapdist(m, s)) > 1e-6)
    return same / len(mine), extra


_CPU: dict[int, float] = {}


def _single(call, poses):
    """Median seconds per call over the poses (after one warm-up); the median CPU seconds of
    this process per call go to ``_CPU[id(call)]`` (less sensitive to other jobs' load)."""
    call(poses[0])
    times, cpu, out = [], [], []
    for T in poses:
        c = time.process_time()
        t = time.perf_counter()
        r = call(T)
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        out.append(r)
    _CPU[id(call)] = float(np.median(cpu))
    return float(np.median(times)), out


# -- peers ----------------------------------------------------------------------------------
def _dh(model):
    if model.notation != "standard_dh" or np.any(model.base != np.eye(4)) or \
            np.any(model.tool != np.eye(4)):
        return None
    th, d, a, al = model.parameters.T
    return th, d, a, al


def peer_ssik(model):
    import ssik

    dh = _dh(model)
    if dh is None:
        return None
    th, d, a, al = dh
    m = ssik.Manipulator.from_dh(al, a, d)

    def call(T):
        return [np.asarray(s.q, dtype=float) - th for s in m.solve(T)]
    return call


def peer_eaik(model):
    """EAIK from DH parameters, or (a URDF model) from the home axes (H, P); the solutions it
    does not flag least-squares."""
    from eaik.IK_DH import DhRobot

    dh = _dh(model)
    if dh is None:
        return peer_eaik_hp(model)
    th, d, a, al = dh
    bot = DhRobot(al, a, d)
    if not bot.hasKnownDecomposition():
        return None

    def call(T):
        s = bot.IK(T)
        return [np.asarray(q) - th for q, ls in zip(s.Q, s.is_LS, strict=True) if not ls]
    return call


def peer_eaik_hp(model, fixed_axes=(), keep_ls=False):
    """EAIK's ``HPRobot`` from the home axes (H, P) of a URDF model, with ``fixed_axes``
    ``[(joint index, value)]`` held (EAIK's locked joints); None without a decomposition.
    The solutions it does not flag least-squares, or all of them with ``keep_ls`` (its 1-D
    search decompositions flag exact solutions least-squares too: the caller verifies)."""
    from eaik.IK_HP import HPRobot

    ax = home_axes(model)
    pts = np.vstack([ax.r, ax.T0[:3, 3]])
    bot = HPRobot(ax.w.copy(), np.vstack([pts[0], np.diff(pts, axis=0)]),
                  fixed_axes=list(fixed_axes))
    R0 = ax.T0[:3, :3]
    if not bot.hasKnownDecomposition():
        return None

    def call_hp(T):
        Tp = T.copy()
        Tp[:3, :3] = T[:3, :3] @ R0.T
        s = bot.IK(Tp)
        return [np.asarray(q) for q, ls in zip(s.Q, s.is_LS, strict=True)
                if keep_ls or not ls]
    return call_hp


def peer_ikgeo(model, kind):
    from ik_geo import Robot

    ax = home_axes(model)
    h = ax.w.tolist()
    pts = np.vstack([ax.r, ax.T0[:3, 3]])
    p = np.vstack([pts[0], np.diff(pts, axis=0)]).tolist()
    if kind == "pieper" and meet(ax, 0, 1) is None:  # offset shoulder
        kind = "pieper-parallel" if parallel(ax, 1, 2) else "pieper-offset"
    ctor = {"three-parallel": Robot.three_parallel_two_intersecting,
            "pieper": Robot.spherical_two_intersecting,
            "pieper-parallel": Robot.spherical_two_parallel,
            "pieper-offset": Robot.spherical}.get(kind, Robot.gen_six_dof)
    bot = ctor(h, p)
    R0 = ax.T0[:3, :3]

    def call(T):
        # ik-geo takes the rotation transposed (checked against its forward_kinematics)
        out = bot.get_ik((T[:3, :3] @ R0.T).T.tolist(), T[:3, 3].tolist())
        return [np.asarray(q) for q, ls in out if not ls]
    return call


def peer_rtb(model):
    if model.name != "puma560":
        return None
    import roboticstoolbox as rtb

    robot = rtb.models.DH.Puma560()
    mine = np.array([[L.theta, L.d, L.a, L.alpha] for L in robot.links])
    if not np.allclose(mine, model.parameters, atol=1e-9):
        return None
    configs = ("lun", "lud", "lfn", "lfd", "run", "rud", "rfn", "rfd")

    def call(T):
        out = []
        for c in configs:
            sol = robot.ikine_a(T, config=c)
            if sol.success:
                out.append(np.asarray(sol.q))
        return out
    return call


# -- runs -----------------------------------------------------------------------------------
def run(n: int, n_single: int, repeat: int = 5, arms=ARMS) -> dict:
    rng = np.random.default_rng(20261201)
    rows = {}
    for name in ARMS:
        q = rng.uniform(-PI, PI, (n, 6))  # drawn for every arm: the same poses either way
        if name not in arms:
            continue
        model = _urdf_arm(name) if name in URDF6 else arm(name)
        prismatic = model.prismatic
        if prismatic.any():  # within the limits, not an angle
            lo, hi = model.lower[prismatic], model.upper[prismatic]
            q[:, prismatic] = lo + (q[:, prismatic] + PI) / (2 * PI) * (hi - lo)
        T = kinestat.fk(model, q)
        ik_all(model, T[:512])  # compile / load the kernels (serial and parallel paths)
        dt = cpu_batch = math.inf
        for _ in range(repeat):  # best of `repeat` (a shared machine: the least disturbed call)
            c = time.process_time()
            t = time.perf_counter()
            res = ik_all(model, T)
            w = time.perf_counter() - t
            if w < dt:
                dt, cpu_batch = w, (time.process_time() - c) / n
        d = _wrapdist(res.q, q[:, None, :])
        complete = float(np.mean(np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1)))
        worst = float(np.nanmax(np.maximum(res.position_error, res.rotation_error)))
        mine = lambda x, m=model: ik_all(m, x)  # noqa: E731
        single, _ = _single(mine, T[:n_single])
        r = {"kinestat": {"method": res.method, "batched_poses_per_s": n / dt,
                          "batched_cpu_us": cpu_batch * 1e6, "single_us": single * 1e6,
                          "single_cpu_us": _CPU[id(mine)] * 1e6, "complete": complete,
                          "mean_solutions": float(res.n_solutions.mean()),
                          "worst_residual": worst}}
        kind = res.method if res.method in ("pieper", "three-parallel") else "general"
        for peer, make in (("ssik", lambda m: peer_ssik(m)), ("eaik", lambda m: peer_eaik(m)),
                           ("ik-geo", lambda m, k=kind: peer_ikgeo(m, k)),
                           ("rtb-ikine_a", lambda m: peer_rtb(m))):
            try:
                call = None if prismatic.any() else make(model)
                if call is None:
                    r[peer] = None
                    continue
                single, sols = _single(call, T[:n_single])
                c, mean, w = _score(model, q[:n_single], sols)
                good = [[x for x in ss if _score(model, [qq], [[x]])[2] < 1e-6]
                        for qq, ss in zip(q[:n_single], sols, strict=True)]
                agree, extra = _agreement([res.solutions((i,)) for i in range(n_single)], good)
                r[peer] = {"single_us": single * 1e6, "batched_poses_per_s": 1.0 / single,
                           "single_cpu_us": _CPU[id(call)] * 1e6,
                           "batched_cpu_us": _CPU[id(call)] * 1e6,
                           "complete": c, "mean_solutions": mean, "worst_residual": w,
                           "count_agrees_with_kinestat": agree,
                           "peer_solutions_kinestat_lacks": extra}
            except Exception as exc:  # noqa: BLE001 - a peer that fails is reported, not fatal
                r[peer] = {"error": f"{type(exc).__name__}: {exc}"[:120]}
        rows[name] = r
    return rows


# -- 7-joint arms, one joint locked ---------------------------------------------------------
def _urdf_arm(name: str):
    """A real 6-joint arm of :data:`URDF6` from its URDF."""
    from tests.urdf_arms import ARMS as URDF_ARMS
    from tests.urdf_arms import arm_path

    tip = "link06" if name == "z1" else URDF_ARMS[name][1]  # the arm, not its gripper
    return kinestat.load(arm_path(name), tip=tip)


def arm7(name: str):
    """``<arm>-lock<J>``: the 7-joint model and the locked joint's index (0-based)."""
    from pathlib import Path

    from tests.urdf_arms import ARMS as URDF_ARMS
    from tests.urdf_arms import arm_path

    base, j = name.split("-lock")
    if base == "iiwa":
        import rtbdata

        path = Path(rtbdata.__file__).parent / "xacro" / "kuka_description" / "kuka_lbr_iiwa" / \
            "urdf" / "lbr_iiwa_14_r820.urdf"
        return kinestat.load(path, tip="tool0"), int(j) - 1
    return kinestat.load(arm_path(base), tip=URDF_ARMS[base][1]), int(j) - 1


def _rounds(calls: dict, poses, rounds: int) -> dict:
    """Interleaved rounds of single calls: per solver, the fastest round's median seconds per
    call, its CPU seconds and the outputs of the first round. ``poses``: one list for every
    round, or a list of ``rounds`` lists (fresh inputs each round)."""
    best, outs = {}, {}
    for i in range(rounds):
        for key, call in calls.items():
            t, out = _single(call, poses[i] if isinstance(poses, list) else poses)
            outs.setdefault(key, out)
            if t < best.get(key, (math.inf,))[0]:
                best[key] = (t, _CPU[id(call)])
    return {k: (best[k][0], best[k][1], outs[k]) for k in calls}


def _verified(model, q, sols):
    """Every returned solution reproduces the pose of ``q`` (residual < 1e-6), and the
    distinct ones among them."""
    ok = [s for s in sols if _score(model, [q], [[s]])[2] < 1e-6]
    return len(ok) == len(sols), ok


def _batch(call, T, repeat: int):
    """The fastest of ``repeat`` calls on the poses ``T``: wall seconds, CPU µs a pose, result."""
    best, cpu, res = math.inf, math.inf, None
    for _ in range(repeat):
        c, t = time.process_time(), time.perf_counter()
        out = call(T)
        w = time.perf_counter() - t
        if w < best:
            best, cpu, res = w, (time.process_time() - c) / len(T) * 1e6, out
    return best, cpu, res


def _calls7(model, j: int, v: float, six) -> dict:
    """The single calls of the 7-joint rows: a pose (fixed value ``v``) or, for the "new
    value" rows, a pair (pose, locked value)."""
    calls = {"kinestat": lambda x: ik_all(model, x, locked={j: v}),
             "kinestat-6R": lambda x: ik_all(six, x)}
    eaik = peer_eaik_hp(model, [(j, v)], keep_ls=True)
    if eaik is not None:
        calls["eaik"] = eaik
    calls["kinestat new value"] = lambda tv: ik_all(model, tv[0], locked={j: tv[1]})
    if eaik is not None:  # a robot built for each value: how EAIK changes a fixed axis
        calls["eaik new value"] = lambda tv: peer_eaik_hp(model, [(j, tv[1])], True)(tv[0])
    return calls


def run7(n: int, n_single: int, repeat: int, rounds: int, arms=ARMS7) -> dict:
    rows = {}
    for k, name in enumerate(ARMS7):
        if name not in arms:
            continue
        model, j = arm7(name)
        rng = np.random.default_rng([20261207, k])
        q = rng.uniform(-PI, PI, (n, model.n))
        qv = rng.uniform(-PI, PI, (rounds * n_single, model.n))
        lo = float(model.lower[j]) if math.isfinite(model.lower[j]) else -PI
        hi = float(model.upper[j]) if math.isfinite(model.upper[j]) else PI
        values = lo + rng.random(len(qv)) * (hi - lo)  # a locked value per pose, in the limits
        v = float(values[0])
        qv[:, j] = values
        q[:, j] = v
        T, Tv = kinestat.fk(model, q), kinestat.fk(model, qv)
        calls = _calls7(model, j, v, fold(model, ((j, v),)))
        calls["kinestat"](T[:512])  # compile / load the kernels
        dt, cpu, res = _batch(calls["kinestat"], T, repeat)
        dt6, cpu6, _ = _batch(calls["kinestat-6R"], T, repeat)
        d = _wrapdist(res.q, q[:, None, :])
        r = {"kinestat": {"method": res.method, "batched_poses_per_s": n / dt,
                          "batched_cpu_us": cpu,
                          "complete": float(np.mean(np.any(np.where(res.valid, d, np.inf)
                                                           < 1e-6, axis=1))),
                          "mean_solutions": float(res.n_solutions.mean()),
                          "worst_residual": float(np.nanmax(np.maximum(
                              res.position_error, res.rotation_error)))},
             "kinestat-6R": {"method": res.method, "batched_poses_per_s": n / dt6,
                             "batched_cpu_us": cpu6}}
        pairs = list(zip(Tv, values.tolist(), strict=True))  # fresh values in every round
        timed = _rounds({key: c for key, c in calls.items() if "new" not in key},
                        T[:n_single], rounds)
        timed.update(_rounds({key: c for key, c in calls.items() if "new" in key},
                             [pairs[i * n_single:(i + 1) * n_single] for i in range(rounds)],
                             rounds))
        if "eaik" not in calls:
            r["eaik"] = None
        for key, (t, cpu_s, sols) in timed.items():
            row = r.setdefault(key, {"method": "", "batched_poses_per_s": None,
                                     "batched_cpu_us": None})
            row.update(single_us=t * 1e6, single_cpu_us=cpu_s * 1e6)
            if key.startswith("eaik"):
                qq, mine = (q, "kinestat") if key == "eaik" else (qv, "kinestat new value")
                checks = [_verified(model, x, ss)
                          for x, ss in zip(qq[:n_single], sols, strict=True)]
                c, mean, w = _score(model, qq[:n_single], sols)
                agree, extra = _agreement([m.solutions() for m in timed[mine][2]],
                                          [ok for _, ok in checks])
                row.update(batched_poses_per_s=1.0 / t, batched_cpu_us=cpu_s * 1e6, complete=c,
                           mean_solutions=mean, worst_residual=w,
                           count_agrees_with_kinestat=agree, peer_solutions_kinestat_lacks=extra,
                           every_solution_reproduces=float(np.mean([a for a, _ in checks])))
        rows[name] = r
    return rows


def _fmt(v, spec):
    return "n/a" if v is None else format(v, spec)


def _print(rows: dict) -> None:
    print(f"{'arm':11} {'solver':18} {'method':24} {'single µs':>10} {'cpu µs':>7} "
          f"{'poses/s':>10} {'cpu µs':>7} {'complete':>8} {'mean #':>7} {'worst res':>10} "
          f"{'same # as ks':>12} {'ks lacks':>8} {'all reproduce':>13}")
    for name, r in rows.items():
        for solver, v in r.items():
            if v is None:
                print(f"{name:11} {solver:18} {'n/a (does not apply)':24}")
                continue
            if "error" in v:
                print(f"{name:11} {solver:18} failed: {v['error']}")
                continue
            print(f"{name:11} {solver:18} {v.get('method', ''):24} "
                  f"{_fmt(v.get('single_us'), '10.1f')} {_fmt(v.get('single_cpu_us'), '7.1f')} "
                  f"{_fmt(v['batched_poses_per_s'], '10.0f')} {_fmt(v['batched_cpu_us'], '7.2f')} "
                  f"{_fmt(v.get('complete'), '8.4f')} {_fmt(v.get('mean_solutions'), '7.2f')} "
                  f"{_fmt(v.get('worst_residual'), '10.1e')} "
                  f"{_fmt(v.get('count_agrees_with_kinestat'), '12.4f')} "
                  f"{_fmt(v.get('peer_solutions_kinestat_lacks'), '8d')} "
                  f"{_fmt(v.get('every_solution_reproduces'), '13.4f')}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="poses per arm for the batched run")
    ap.add_argument("--single", type=int, default=200, help="poses for single-call timing")
    ap.add_argument("--repeat", type=int, default=5,
                    help="batched kinestat calls per arm; the fastest is reported")
    ap.add_argument("--rounds", type=int, default=5,
                    help="interleaved rounds of single calls (7-joint arms); the fastest counts")
    ap.add_argument("--arms", default=",".join(ARMS + ARMS7),
                    help=f"comma-separated subset of {ARMS + ARMS7}")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    arms = tuple(a.arms.split(","))
    unknown = sorted(set(arms) - set(ARMS + ARMS7))
    if unknown:
        ap.error(f"unknown arm(s) {unknown}; expected some of {ARMS + ARMS7}")
    rows = run(a.n, a.single, a.repeat, arms)
    rows.update(run7(a.n, a.single, a.repeat, a.rounds, arms))
    meta = {"cpus": os.cpu_count(), "numba_threads": __import__("numba").get_num_threads(),
            "machine": platform.platform(), "load_avg": os.getloadavg()}
    if a.json:
        print(json.dumps({"meta": meta, "rows": rows}, indent=1))
        return 0
    print(f"# ik_all benchmark  n={a.n}  single={a.single}  repeat={a.repeat}  "
          f"rounds={a.rounds}  {meta}")
    _print(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
