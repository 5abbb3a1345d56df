"""The Jacobian in the twist form of Nadkarni eq. 4-11, batched.

Column j is ``[u_j; h_j u_j − u_j × ρ_j]`` for revolute (h = 0) and screw joints, and
``[0; u_j]`` for prismatic joints, where ``u_j`` is the unit joint axis and ``ρ_j`` any point
on it, both in the base frame. With twists ``[ω; v_O]`` (v_O the velocity of the point at the
origin), ``J(q) · δq = B`` is Nadkarni's eq. 4-11 literally.
"""

from __future__ import annotations

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial import fk as _fkmod
from kinestat.serial._kernel_cache import kernel_data
from kinestat.serial.fk import _F64, _ND, _as_q, _empty

__all__ = ["jacobian", "jacobian_from_frames", "fk_and_jacobian"]


def jacobian_from_frames(model: ChainModel, frames: np.ndarray) -> np.ndarray:
    """Jacobian ``(..., 6, n)`` from the link frames returned by
    :func:`~kinestat.serial.fk.fk_frames` (the NumPy form of :func:`jacobian`).

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> from kinestat.serial.fk import fk_frames
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    >>> J = jacobian_from_frames(arm, fk_frames(arm, [0.3, 0.4]))
    >>> bool(np.allclose(J, jacobian(arm, [0.3, 0.4])))
    True
    """
    F = frames[..., :-1, :, :]
    u = F[..., :3, 2]
    rho = F[..., :3, 3]
    h = model.pitches[:, None]
    pris = model.prismatic[:, None]
    w = np.where(pris, 0.0, u)
    v = np.where(pris, u, h * u - np.cross(u, rho))
    return np.swapaxes(np.concatenate([w, v], axis=-1), -1, -2)


def jacobian(model: ChainModel, q) -> np.ndarray:
    """Space Jacobian ``(..., 6, n)`` mapping joint rates to the end twist ``[ω; v_O]``.

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]])  # planar RR
    >>> J = jacobian(arm, [0.0, 0.0])
    >>> J[2], J[4]  # ω_z and v_Oy: joint 2's axis passes through x = 1
    (array([1., 1.]), array([ 0., -1.]))
    """
    # as in fk: the last model's one-configuration call with q a float64 vector goes straight to
    # the compiled entry point
    last = _last  # read once: another thread may replace it
    if last[0] is model and type(q) is _ND and q.ndim == 1 and q.dtype is _F64:
        J = _empty(last[4])
        if not last[2](last[1], q, J):
            return J
    return _jacobian_checked(model, q)


#: :data:`kinestat.serial.fk._last` for the Jacobian, with the Jacobian's shape last
_last: tuple = (object(), 0.0, None, None, (6, 0))  # matches no argument (not even None)


def _jacobian_checked(model: ChainModel, q) -> np.ndarray:
    """:func:`jacobian` by the checked path; a single configuration's model is remembered."""
    global _last
    _fkmod.check_model(model)
    J = _fkmod.evaluate(model, q, _jac_entry, _fkmod.kernels().jacobian_batch, (6, model.n))
    if J.ndim == 2:
        last = _fkmod.one_call(model, _JAC_ONE or _jac_entry())
        _last = (*last, last[3].jshape)
    return J


_JAC_ONE = None


def _jac_entry():
    """The compiled single-configuration Jacobian entry point, fetched once."""
    global _JAC_ONE
    _JAC_ONE = _fkmod.kernels().single_entry("jacobian_one")
    return _JAC_ONE


def fk_and_jacobian(model: ChainModel, q) -> tuple[np.ndarray, np.ndarray]:
    """End poses ``(..., 4, 4)`` and Jacobians ``(..., 6, n)`` in one pass.

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    >>> T, J = fk_and_jacobian(arm, np.zeros((3, 2)))
    >>> T.shape, J.shape
    ((3, 4, 4), (3, 6, 2))
    """
    q = _as_q(model, q)
    d = kernel_data(model)
    lead = q.shape[:-1]
    Q = np.ascontiguousarray(q.reshape(-1, model.n))
    T = np.empty((Q.shape[0], 4, 4))
    J = np.empty((Q.shape[0], 6, model.n))
    if _fkmod.kernels().fk_jacobian_batch(d.constants, d.kinds, d.pitches, Q, T, J):
        raise InputError("q contains NaN or infinity")
    return T.reshape(lead + (4, 4)), J.reshape(lead + (6, model.n))
