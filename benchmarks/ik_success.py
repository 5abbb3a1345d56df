"""Success rate of numerical IK (``kinestat.ik``, default settings) on real arms.

For each arm: N random configurations uniformly within the joint limits (continuous joints in
[-pi, pi)), their FK poses as targets (so every target is reachable within the limits), solved
from the default start (the model's q_home) with ``kinestat.ik`` defaults, or with
``--restarts R`` to compare budgets. Prints success rate, misses and wall time per target.

    .venv/bin/python benchmarks/ik_success.py --n 1000 [--restarts 20,50]
"""

from __future__ import annotations

import argparse
import time
from importlib.metadata import distribution

import numpy as np

import kinestat

ERD = "cmeel.prefix/share/example-robot-data/robots"
ARMS = {
    "puma560": ("puma560", {}),
    "puma762": ("puma762", {}),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", {"tip": "tool0"}),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", {"tip": "tool0"}),
    "ur3": ("ur_description/urdf/ur3_robot.urdf", {"tip": "tool0"}),
    "kinova-j2s6s200": ("kinova_description/robots/kinova.urdf",
                        {"tip": "j2s6s200_end_effector"}),
    "panda": ("panda_description/urdf/panda.urdf", {"tip": "panda_hand_tcp"}),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", {}),
    "so100": ("so_arm_description/urdf/so100.urdf", {}),
}


def load_arm(name: str):
    spec, kw = ARMS[name]
    if spec.endswith(".urdf"):
        from kinestat.io.urdf import read_urdf

        path = distribution("example-robot-data").locate_file(f"{ERD}/{spec}")
        return read_urdf(path, **kw)
    return kinestat.load(spec)


def random_q(model, n: int, rng) -> np.ndarray:
    lo = np.where(np.isfinite(model.lower), model.lower, -np.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, np.pi)
    return lo + (hi - lo) * rng.random((n, model.n))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--arms", default=",".join(ARMS))
    ap.add_argument("--restarts", default="")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    budgets = [int(r) for r in a.restarts.split(",")] if a.restarts else [None]
    for name in a.arms.split(","):
        m = load_arm(name)
        rng = np.random.default_rng(a.seed)
        T = kinestat.fk(m, random_q(m, a.n, rng))
        kinestat.ik(m, T[:2])  # compile outside the timing
        for R in budgets:
            kw = {} if R is None else {"restarts": R}
            t0 = time.perf_counter()
            r = kinestat.ik(m, T, **kw)
            dt = time.perf_counter() - t0
            ok = np.asarray(r.success)
            print(f"{name:16s} n={m.n} restarts={'default' if R is None else R:>7} "
                  f"success={ok.mean():.4f} misses={int((~ok).sum())}/{a.n} "
                  f"mean attempts={np.mean(r.attempts):.2f} "
                  f"time/target={dt / a.n * 1e3:.2f} ms", flush=True)


if __name__ == "__main__":
    main()
