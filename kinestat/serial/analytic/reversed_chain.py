"""Arms whose first three axes meet (a spherical shoulder) solved as their reversed chain, whose
last three axes meet: a ``pieper`` arm (:mod:`kinestat.serial.analytic.closed_form`).

``T = C0 Z(q1) C1 ⋯ Z(q6) C6`` gives ``T⁻¹ = C6⁻¹ Z(−q6) C5⁻¹ ⋯ Z(−q1) C0⁻¹``, and
``Z(−q) = F Z(q) F`` with ``F = Rx(π)`` (it flips the y and z axes; for a turn about z and a
slide along z alike). So ``T⁻¹`` is the chain ``C'0 = C6⁻¹ F``, ``C'k = F C(6−k)⁻¹ F``,
``C'6 = F C0⁻¹`` in the joints ``q' = (q6, …, q1)``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic.geometry import DERIVED
from kinestat.serial.analytic.result import IKAllResult

__all__ = ["reverse", "invert_poses", "unreverse", "bind_one"]

_F = np.diag([1.0, -1.0, -1.0, 1.0])


def _inv_all(C: np.ndarray) -> np.ndarray:
    """The inverses of rigid transforms ``(k, 4, 4)``."""
    out = np.zeros(C.shape)
    Rt = np.swapaxes(C[:, :3, :3], -1, -2)
    out[:, :3, :3] = Rt
    out[:, :3, 3] = -(Rt @ C[:, :3, 3:])[..., 0]
    out[:, 3, 3] = 1.0
    return out


@lru_cache(maxsize=64)
def reverse(model: ChainModel) -> ChainModel:
    """The chain from the flange to the base (joints in reverse order, see the module)."""
    Ci = _inv_all(np.asarray(model.constants)[::-1])  # C(n)⁻¹, ..., C0⁻¹ in one step
    Cr = _F @ Ci @ _F  # C'k = F C(n−k)⁻¹ F, and C'0 = C(n)⁻¹ F, C'n = F C0⁻¹ (F F = I):
    Cr[0] = Ci[0] @ _F
    Cr[-1] = _F @ Ci[-1]
    rev = ChainModel(name=f"{model.name} (reversed)", joints=tuple(reversed(model.joints)),
                     constants=Cr, length_unit=model.length_unit,
                     q_home=np.asarray(model.q_home)[::-1])
    DERIVED.add(rev)  # its pairs are the model's
    return rev


def invert_poses(T: np.ndarray) -> np.ndarray:
    """``T⁻¹`` of rigid poses ``(..., 4, 4)``."""
    T = np.asarray(T, dtype=float)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    out = np.zeros(T.shape)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def unreverse(res: IKAllResult) -> IKAllResult:
    """The reversed chain's result in the model's joint order."""
    fields = {f: getattr(res, f) for f in ("valid", "position_error", "rotation_error",
                                           "singular", "family_sign", "family_value",
                                           "n_solutions", "reason", "method", "tol")}
    n = res.q.shape[-1]
    fields["q"] = res.q[..., ::-1]
    fields["family_joints"] = None if res.family_joints is None else \
        tuple(n - 1 - j for j in res.family_joints)
    fields["family_curve"] = None
    return IKAllResult(**fields)


_ROW3 = np.array([0.0, 0.0, 0.0, 1.0])


def bind_one(rev_data: dict):
    """The single-pose call of a reversed-chain model: ``one(T (1, 4, 4) plain, tol)`` inverts
    the pose, runs the reversed chain's bound single call (``rev_data["one"]``, see
    :func:`kinestat.serial.analytic.closed_form.solve_pieper_compiled`) and puts the joints
    back in order; None where that call is not bound yet or returns None (the caller then
    takes the full path)."""

    def one(T, tol):
        rone = rev_data.get("one")
        if rone is None:
            return None
        Rt = T[0, :3, :3].T
        Ti = np.empty((1, 4, 4))
        Ti[0, :3, :3] = Rt
        Ti[0, :3, 3] = -(Rt @ T[0, :3, 3])
        Ti[0, 3] = _ROW3
        res = rone(Ti, tol)
        if res is None:
            return None
        fields = dict(res.__dict__)
        q = res.q
        fields["q"] = q[..., ::-1]
        fj = res.family_joints
        if fj is not None:
            n = q.shape[-1]
            fields["family_joints"] = (n - 1 - fj[0], n - 1 - fj[1])
        fields["family_curve"] = None
        obj = object.__new__(IKAllResult)
        obj.__dict__.update(fields)
        return obj
    return one
