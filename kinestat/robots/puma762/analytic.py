"""The PUMA 762 closed form (Vibhute 2011 §2.2.3) as an instance of the one all-solutions
result type.

The thesis's reverse analysis (:func:`kinestat.robots.puma762.reverse.reverse_batch_pose`: eight
branches ``4·i1 + 2·i3 + i5``, wrist-singular families θ6 − θ4 = const at θ5 = 0 and
θ4 + θ6 = const at θ5 = 180°) is adapted here to an :class:`IKAllResult` (``q (…, 8, 6)``,
``valid (…, 8)``, families on the joint pair (4, 6)), and its thesis-specific description of the
end effector — tool point ``P_tool_F``, sixth axis ``S6_F``, link direction ``a67_F`` — stays as
an adapter (:func:`ik_all_thesis`). ``ik_all(model, T, method="puma762")`` runs it for a model
whose geometry is the PUMA 762's (:func:`is_puma762`, e.g. ``kinestat.load("puma762")``).
"""

from __future__ import annotations

import dataclasses
import math
from functools import lru_cache

import numpy as np

from kinestat.mechanism.chain import ChainModel, from_modified_dh
from kinestat.robots.puma762 import METHOD
from kinestat.robots.puma762 import params as _params
from kinestat.robots.puma762.forward import frame6
from kinestat.robots.puma762.reverse import ReverseBatch, reverse_batch_pose, status_message
from kinestat.serial.analytic._common import pack
from kinestat.serial.analytic.result import IKAllResult

__all__ = ["METHOD", "puma762_chain", "is_puma762", "result_from_reverse", "solve_puma762",
           "ik_all_thesis"]


_FAMILY_JOINTS = (3, 5)  # θ4 and θ6 (0-based)


@lru_cache(maxsize=1)
def puma762_chain() -> ChainModel:
    """The PUMA 762 as a chain (Crane–Duffy modified DH, Vibhute Table 2-2, S6 = 125 mm), joint
    limits in joint angles (φ1 = axis 1 − 180°), built from :mod:`kinestat.robots.puma762`'s
    link table; equal to ``kinestat.load("puma762")``.

    >>> m = puma762_chain()
    >>> m.n, m.length_unit, is_puma762(m)
    (6, 'mm', True)
    """
    alpha = (0.0, *np.radians(_params.ALPHA_DEG))
    a = (0.0, *_params._A)
    d = (0.0, *_params._S)
    rows = np.column_stack([alpha, a, np.zeros(6), d])
    lim_deg = np.asarray(_params.AXIS_LIMITS_DEG, dtype=float) - np.degrees(
        _params.AXIS_OFFSET)[:, None]
    lim_deg[0] += 360.0  # φ1 = axis 1 − 180° taken in [20°, 340°] as in data/models
    lim = np.radians(lim_deg)
    return from_modified_dh(rows, limits=lim, names=[str(i + 1) for i in range(6)],
                            name="puma762", length_unit="mm",
                            description="PUMA 762 (Vibhute 2011 Table 2-2, S6 = 125 mm)")


def is_puma762(model: ChainModel, *, atol: float = 1e-9) -> bool:
    """True when ``model`` is six revolute joints with the PUMA 762's geometry in millimetres
    (its constant transforms equal the thesis's to ``atol``), so the thesis closed form applies.

    >>> import kinestat
    >>> is_puma762(kinestat.load("puma762")), is_puma762(kinestat.load("puma560"))
    (True, False)
    """
    if model.n != 6 or model.length_unit != "mm" or bool(np.any(model.prismatic)):
        return False
    if any(j.kind != "revolute" for j in model.joints):
        return False
    ref = puma762_chain().constants
    return bool(np.allclose(model.constants, ref, rtol=0.0, atol=atol))


def _families(batch: ReverseBatch) -> tuple[np.ndarray, np.ndarray]:
    """Family sign σ and value of ``θ4 + σ θ6`` from the thesis's (sum | difference) form:
    θ4 + θ6 = v at θ5 = 180° (σ = +1); θ6 − θ4 = v, i.e. θ4 − θ6 = −v, at θ5 = 0 (σ = −1)."""
    fsum = batch.family_sum
    sign = np.where(batch.singular, np.where(fsum, 1.0, -1.0), 0.0)
    v = batch.family_value
    value = np.where(fsum, v, np.mod(-v + math.pi, 2.0 * math.pi) - math.pi)
    return sign, np.where(batch.singular, value, np.nan)


def result_from_reverse(model: ChainModel, batch: ReverseBatch, T_base_6: np.ndarray,
                        *, tol: float = 1e-9) -> IKAllResult:
    """Adapt the eight branches of the thesis's reverse analysis ``batch`` (poses
    ``T_base_6 (N, 4, 4)`` of frame 6) to an :class:`IKAllResult`: every branch verified by
    :func:`kinestat.fk` on ``model``, duplicates dropped, valid slots first (8 slots), wrist
    families on joints (4, 6) and, where no branch exists, the thesis's reason (which of φ1,
    θ3 has no real solution)."""
    sign, value = _families(batch)
    # one member per family, as the generic solvers give it (θ4 = 0, θ6 = σ · value), so that
    # the two θ5 branches meeting at a singularity collapse to one family
    q = batch.q.copy()
    q[..., 3] = np.where(batch.singular, 0.0, q[..., 3])
    q[..., 5] = np.where(batch.singular, sign * value, q[..., 5])
    res = pack(model, q, batch.valid, T_base_6, _params.N_BRANCHES, tol=tol,
               method=METHOD, reason_none="", singular=batch.singular, family_sign=sign,
               family_value=value, family_joints=_FAMILY_JOINTS)
    status = np.asarray(batch.status).reshape(-1)
    msgs = {int(s): status_message(int(s)) for s in np.unique(status)}
    reason = np.array([
        "" if res.n_solutions[i] > 0 else
        (msgs[int(s)] if int(s) != _params.STATUS_OK else
         "no branch reproduces the pose within the tolerance")
        for i, s in enumerate(status)], dtype=object)
    return dataclasses.replace(res, reason=reason)


def solve_puma762(model: ChainModel, T: np.ndarray, *, tol: float = 1e-9,
                  backend: str = "numba") -> IKAllResult:
    """All solutions (8 slots) of the PUMA 762 by the thesis closed form; ``T (N, 4, 4)``
    poses of frame 6 in the fixed frame (mm). ``model`` must satisfy :func:`is_puma762`."""
    batch = reverse_batch_pose(T, verify=True, tol=tol, backend=backend)
    return result_from_reverse(model, batch, T, tol=tol)


def ik_all_thesis(tool_point, s6, a67, tool_point_6=(0.0, 0.0, 0.0), *, tol: float = 1e-9,
                  unit_tol: float = 1e-6) -> IKAllResult:
    """Every PUMA 762 solution for the thesis's end-effector description, as an
    :class:`IKAllResult` (Vibhute §2.2.3): tool point ``P_tool_F (…, 3)`` mm, unit sixth axis
    ``S6_F`` and link direction ``a67_F`` (perpendicular), tool point in frame 6
    ``P_tool_6``. The batch shape is the inputs' broadcast shape.

    >>> from kinestat.robots.puma762.closed_form import forward
    >>> f = forward(np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6]))
    >>> res = ik_all_thesis(f.tool_point, f.s6, f.a67)
    >>> res.method, int(res.n_solutions), res.q.shape
    ('puma762', 8, (8, 6))
    """
    T = frame6(tool_point, s6, a67, tool_point_6, tol=unit_tol)
    shape = T.shape[:-2]
    Tf = np.ascontiguousarray(T.reshape(-1, 4, 4))
    res = solve_puma762(puma762_chain(), Tf, tol=tol)

    def r(a):
        return a.reshape(shape + a.shape[1:])

    return dataclasses.replace(
        res, q=r(res.q), valid=r(res.valid), position_error=r(res.position_error),
        rotation_error=r(res.rotation_error), singular=r(res.singular),
        family_sign=r(res.family_sign), family_value=r(res.family_value),
        n_solutions=r(res.n_solutions), reason=r(res.reason))
