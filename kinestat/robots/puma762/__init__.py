"""The PUMA 762 of Vibhute 2011 — one robot, in one package.

- :mod:`.closed_form` — the forward and reverse position analysis in closed form (Vibhute
  §2.2.3, App. C): :mod:`.params` (link table, joint limits, axis 1 = φ1 + 180°),
  :mod:`.forward`, :mod:`.reverse`, :mod:`.selection` (least-motion choice within the axis
  limits); compiled kernels in ``_kernels``/``_cycle_kernels``, the NumPy reference in
  ``_reference``.
- :mod:`.analytic` — that closed form as an all-solutions result: the ``"puma762"`` method of
  :func:`kinestat.ik_all` (registered with :mod:`kinestat.serial.ik_methods` when this package
  is imported), the robot as a :class:`~kinestat.mechanism.chain.ChainModel`
  (:func:`~.analytic.puma762_chain`, equal to ``kinestat.load("puma762")``).
- :mod:`.arm` — :class:`~.arm.Puma762Arm`, the robot behind the controller's
  :class:`kinestat.control.arm.Arm` protocol, and ``THESIS_ARM``.
- :mod:`.axes` — its drives in the thesis's cell: Galil axes A..F, encoder scales, the joint-1
  offset, the axis 4 → 5 coupling and its compensation, the thesis's tool point.
- :mod:`.homing` — the homing program's offsets (App. D.4); :mod:`.layout` — where the
  robot's index marks and pots are (the simulated robot's own data).

Importing this package is cheap: the names below load with their module on first use.
"""

from __future__ import annotations

import lazy_loader

from kinestat.serial.ik_methods import IKMethod, register

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'analytic': ['ik_all_thesis', 'is_puma762', 'puma762_chain'],
        'arm': ['Puma762Arm', 'THESIS_ARM'],
        'axes': ['AXIS4_TO_5_COUPLING', 'AXIS_DEG_PER_COUNT', 'THESIS_TOOL_POINT_6',
                 'axis45_compensation'],
        'params': ['AXIS_LIMITS_DEG'],
    },
)

METHOD = "puma762"
"""The ``method`` name of the thesis's closed form in :func:`kinestat.ik_all`."""


def _applies(model) -> bool:
    from kinestat.robots.puma762.analytic import is_puma762  # lazy: its kernels on first use

    return is_puma762(model)


def _solve(model, T, *, tol: float = 1e-9, backend: str = "numba"):
    from kinestat.robots.puma762.analytic import solve_puma762  # lazy: its kernels on first use

    return solve_puma762(model, T, tol=tol, backend=backend)


register(IKMethod(METHOD, _applies, _solve,
                  "the PUMA 762's geometry (millimetres, Vibhute Table 2-2)"))
