"""The first run's kernel compilation, said out loud and kept out of anyone's timing (issue 16).

kinestat's kernels are compiled by Numba on first use and cached on disk (``__pycache__`` next
to the source, or ``NUMBA_CACHE_DIR``). Only what a command uses is compiled or loaded: the
``kinestat`` command watches Numba's compilations (:func:`announce_compiles`) and, once they have
taken more than :data:`NOTICE_AFTER_S` in a process, says "compiling kernels (first run only)…"
on stderr. :func:`warm_kernels` compiles kernel groups ahead of time: ``kinestat warmup`` (hidden;
``make run`` calls it) compiles the groups ``kinestat control`` runs (:data:`RUN_GROUPS`),
``kinestat warmup --all`` every group, cold groups in parallel processes, one an idle core.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import os
import subprocess
import sys
import time
from collections.abc import Iterator

import numpy as np

from kinestat.cli._compile_watch import announce_compiles, say_compiling

#: kernel groups -> the module holding their compiled kernels
KERNELS: dict[str, str] = {
    "serial": "kinestat.serial._kernels",
    "ik": "kinestat.serial._ik_kernels",
    "puma762": "kinestat.robots.puma762._kernels",
    "cycle": "kinestat.robots.puma762._cycle_kernels",
    "stiffness": "kinestat.parallel._stiffness_kernels",
    "platform": "kinestat.parallel._fk_kernels",
    "kinestatic": "kinestat.parallel._kinestatic_kernels",
}
#: the groups ``kinestat control`` (the run ``make run`` starts) uses with its defaults: the
#: platform's forward kinematics and the PUMA 762 closed form; ``kinestat warmup`` compiles these
RUN_GROUPS: tuple[str, ...] = ("platform", "puma762")
#: kernel groups compiled on demand by the command that uses them (not by ``kinestat warmup``)
ON_DEMAND: dict[str, str] = {
    "ik_all_closed": "kinestat.serial.analytic._cf_kernels",
    "ik_all_general": "kinestat.serial.analytic._rr_kernels",
    "ik_all_decoupled": "kinestat.serial.analytic._decoupled_kernels",
    "ik_all_middle": "kinestat.serial.analytic._middle_kernels",
    "ik_all_locked": "kinestat.serial.analytic._locked_kernels",
}
def _index_paths(module_name: str) -> list[str]:
    from numba.core.dispatcher import Dispatcher  # lazy: start-up (Numba ~0.5 s)

    mod = importlib.import_module(module_name)
    paths = []
    for name, obj in vars(mod).items():
        if isinstance(obj, Dispatcher) and not name.startswith("_"):
            cache_file = getattr(getattr(obj, "_cache", None), "_cache_file", None)
            path = getattr(cache_file, "_index_path", None)
            if path:
                paths.append(path)
    return paths


def is_cold(group: str) -> bool:
    """True when no public kernel of ``group`` has a cache index on disk (it will compile)."""
    paths = _index_paths(KERNELS.get(group) or ON_DEMAND[group])
    return bool(paths) and not any(os.path.exists(p) for p in paths)


@contextlib.contextmanager
def compiling_notice(*groups: str) -> Iterator[bool]:
    """Announce the compilations of the block once they take over a second
    (:func:`announce_compiles`); yields whether one of ``groups`` is cold."""
    announce_compiles()
    yield any(is_cold(g) for g in groups)


def _warm_serial() -> None:
    from kinestat.io.library import load  # lazy: start-up
    from kinestat.serial.fk import fk, fk_frames  # lazy: start-up (numba)
    from kinestat.serial.jacobian import jacobian  # lazy: start-up (numba)

    m = load("puma762")
    q = np.zeros(m.n)
    fk(m, q), fk(m, q[None]), fk_frames(m, q), jacobian(m, q), jacobian(m, q[None])
    fk(m, np.zeros((4096, m.n)))  # a batch this large runs over the cores (another kernel)


def _warm_ik() -> None:
    from kinestat.io.library import load  # lazy: start-up
    from kinestat.serial.fk import fk  # lazy: start-up (numba)
    from kinestat.serial.ik import ik  # lazy: start-up (numba)

    m = load("puma762")
    ik(m, fk(m, np.full(m.n, 0.1)), restarts=1, max_iter=5)


def _warm_puma762() -> None:
    from kinestat.robots.puma762 import closed_form as puma762  # lazy: start-up (numba)

    puma762.reverse([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])


def _warm_cycle() -> None:
    """The control cycle's single-pose kernels, with the argument types the controller passes
    (kinestat.control.controller._solve_counts and move_command)."""
    from kinestat.robots.puma762 import closed_form as puma762  # lazy: start-up (numba)
    from kinestat.robots.puma762._cycle_kernels import grid_nearest  # lazy: start-up (numba)

    q = np.full(6, 0.3)
    p6 = np.array([0.0, 0.0, 235.0])
    f = puma762.forward(q, p6)
    puma762.select_axis_one(f.tool_point, f.s6, f.a67, p6, q, puma762.AXIS_LIMITS_DEG)
    puma762.pose_one(q)
    cs = np.zeros((1, 2))  # cos/sin tables (vernier.vernier_tables' layouts)
    grid_nearest(cs, cs, cs, cs, np.zeros((1, 1, 2)), np.zeros(2), p6.copy(), p6.copy(),
                 np.array([0.0, 0.0, 1.0]), 1e-3, 0.05, 1e-4, 0)


def _warm_stiffness() -> None:
    from kinestat.io.library import prototype  # lazy: start-up
    from kinestat.parallel.stiffness import (  # lazy: start-up (numba)
        pinned_tip_step,
        stiffness_axis_trusted,
        tip_compliance_one,
    )

    p = prototype()
    K = stiffness_axis_trusted(p, p.home_pose)
    tip = np.array([0.0, 0.0, 100.0])
    tip_compliance_one(K, tip)
    pinned_tip_step(p, p.home_pose, K, tip, np.full(3, 0.01), np.ones(3))


def _warm_platform() -> None:
    """All-mode FK (fk_list), tracking FK with its nearest-mode test (fk_tracking) and the
    compiled line Jacobian (line_jacobian_trusted)."""
    from kinestat.io.library import prototype  # lazy: start-up
    from kinestat.parallel.fk import fk_list, fk_tracking  # lazy: start-up (numba)
    from kinestat.parallel.legs import leg_lengths, line_jacobian_trusted  # lazy: start-up

    p = prototype()
    fk_list(p, leg_lengths(p, p.home_pose))
    fk_tracking(p, leg_lengths(p, p.home_pose), p.home_pose)
    line_jacobian_trusted(p, p.home_pose)


def _warm_kinestatic() -> None:
    """The follow law's one-stiffness kernels (kinestat.parallel.kinestatic.solve_one and
    compose_twist_line's singularity check)."""
    from kinestat.parallel.kinestatic import compose_twist_line, solve_one  # lazy: numba

    K = np.diag([10.0, 10.0, 10.0, 1.0, 1.0, 1.0])
    w = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    solve_one(K, w)
    compose_twist_line(K, w, np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0]), 2.0 * w)


_WARM = {"serial": _warm_serial, "ik": _warm_ik, "puma762": _warm_puma762,
         "cycle": _warm_cycle, "stiffness": _warm_stiffness, "platform": _warm_platform,
         "kinestatic": _warm_kinestatic}


def warm_kernels(groups: tuple[str, ...] = tuple(KERNELS)) -> dict[str, float]:
    """Compile (or load from the cache) the kernels of ``groups`` in this process; seconds per
    group."""
    took = {}
    for g in groups:
        t0 = time.perf_counter()
        _WARM[g]()
        took[g] = time.perf_counter() - t0
    return took


#: compile seconds of each group with an empty cache (2 cores at load ~4, 2026-12-07): only the
#: order in which :func:`compile_groups` shares the groups out between processes
_COST_S = {"platform": 17.0, "ik": 9.0, "stiffness": 8.0, "puma762": 7.0, "serial": 5.0,
           "cycle": 4.0, "kinestatic": 1.0}
_CHILD = ("import json, sys; from kinestat.cli._compile import warm_kernels; "
          "print(json.dumps(warm_kernels(tuple(sys.argv[1:]))))")


def idle_cores() -> int:
    """The CPU cores this process may run on less the machine's load (at least 1): on a busy
    machine a second compiling process only adds its own start-up."""
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        n = os.cpu_count() or 1
    try:
        busy = os.getloadavg()[0]
    except OSError:  # pragma: no cover - no load average
        busy = 0.0
    return max(1, min(n, round(n - busy)))


def _shares(groups: list[str], jobs: int) -> list[list[str]]:
    """``groups`` dealt to ``jobs`` processes, the costliest first to the least loaded."""
    bins: list[list[str]] = [[] for _ in range(jobs)]
    load = [0.0] * jobs
    for g in sorted(groups, key=lambda g: -_COST_S.get(g, 1.0)):
        k = load.index(min(load))
        bins[k].append(g)
        load[k] += _COST_S.get(g, 1.0)
    return [b for b in bins if b]


def _compile_in_processes(groups: list[str], jobs: int) -> dict[str, float]:
    """Compile ``groups`` in ``jobs`` child processes at once (each writes Numba's cache);
    the groups of a child that fails are left to the caller."""
    children = [(share, subprocess.Popen([sys.executable, "-c", _CHILD, *share],
                                         stdout=subprocess.PIPE, text=True))
                for share in _shares(groups, jobs)]
    took: dict[str, float] = {}
    for _share, child in children:
        out, _ = child.communicate()
        if child.returncode == 0:
            with contextlib.suppress(ValueError):
                took.update(json.loads(out.strip().splitlines()[-1]))
    return took


def compile_groups(groups: tuple[str, ...], jobs: int | None = None) -> dict[str, float]:
    """Compile (or load) the kernels of ``groups``, the cold ones in up to ``jobs`` processes
    (default: one an idle core), saying so on stderr; seconds per group (a child's own time)."""
    cold = [g for g in groups if is_cold(g)]
    if cold:
        say_compiling()
    jobs = min(jobs or idle_cores(), len(cold))
    took = _compile_in_processes(cold, jobs) if jobs >= 2 else {}
    took.update(warm_kernels(tuple(g for g in groups if g not in took)))
    return {g: took[g] for g in groups}


def warm_cold_kernels(groups: tuple[str, ...] = RUN_GROUPS) -> None:
    """Compile the cold groups among ``groups`` now (default: those ``kinestat control`` runs),
    saying so on stderr, so that a run's first cycle does not pay for it."""
    cold = tuple(g for g in groups if is_cold(g))
    if cold:
        compile_groups(cold)
