"""Forward kinematics (fk) of serial chains, batched — the theses' "forward analysis".

``T_base_end(q) = C0 · Z(q1) · C1 · … · Z(qn) · Cn`` (DESIGN.md; the lecture notes'
``H_n^0 = H_1^0 H_2^1 … H_n^{n-1}``).

:func:`fk` always runs the compiled kernels (:mod:`kinestat.serial._kernels`); the plain NumPy
implementation they are tested against is :func:`kinestat.serial._reference.fk_reference`
(private, for tests). The kernels' per-model arrays live in :mod:`kinestat.serial._kernel_cache`.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.mechanism.joints import JointKind
from kinestat.serial._kernel_cache import kernel_data
from kinestat.serial.chunks import CHUNK_ROWS, chunk_slices

__all__ = ["joint_motion", "fk", "forward_analysis", "fk_frames", "joint_axes", "iter_fk",
           "CHUNK_ROWS"]


def joint_motion(model: ChainModel, q: np.ndarray) -> np.ndarray:
    """The joint transforms ``Z(qi)``, shape ``(..., n, 4, 4)``.

    Revolute ``Rz(q)``, prismatic ``Tz(q)``, screw ``Rz(q) Tz(h q)`` (Nadkarni eq. 2-14).

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> slider = from_standard_dh([[0.0, 0.0, 0.0, 0.0]], ["prismatic"])
    >>> joint_motion(slider, np.array([2.5]))[0, :3, 3]
    array([0. , 0. , 2.5])
    """
    q = np.asarray(q, dtype=float)
    kinds = model.kind_codes
    pris = kinds == JointKind.PRISMATIC
    ang = np.where(pris, 0.0, q)
    c, s = np.cos(ang), np.sin(ang)
    Z = np.zeros(q.shape + (4, 4))
    Z[..., 0, 0] = c
    Z[..., 0, 1] = -s
    Z[..., 1, 0] = s
    Z[..., 1, 1] = c
    Z[..., 2, 2] = 1.0
    Z[..., 3, 3] = 1.0
    Z[..., 2, 3] = (np.where(pris, q, 0.0)
                    + np.where(kinds == JointKind.SCREW, model.pitches * q, 0.0))
    return Z


def _as_q(model: ChainModel, q) -> np.ndarray:
    check_model(model)
    if type(q) is not np.ndarray or q.dtype != np.float64:
        try:
            q = np.asarray(q, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InputError(f"q must be numbers of shape (..., {model.n}): {exc}") from exc
    if q.ndim == 0 or q.shape[-1] != model.n:
        raise InputError(
            f"q must have shape (..., {model.n}) for model {model.name!r}, got {q.shape}"
        )
    return q


def check_model(model) -> None:
    """Raise :class:`~kinestat.errors.InputError` unless ``model`` is a ChainModel."""
    if not isinstance(model, ChainModel):
        raise InputError(f"model must be a ChainModel (use kinestat.load), got "
                         f"{type(model).__name__}")


_FK_ONE = None


def kernels():
    """The compiled kernel module, imported on the first compiled call (Numba's import is most
    of a fresh process's start-up; :func:`fk_frames` and :func:`joint_motion` need none)."""
    k = sys.modules.get("kinestat.serial._kernels")
    if k is None:
        from kinestat.serial import _kernels as k  # lazy: start-up (Numba)
    return k


def _fk_entry():
    """The compiled single-configuration FK entry point, fetched once."""
    global _FK_ONE
    _FK_ONE = kernels().single_entry("fk_one")
    return _FK_ONE


def _nonfinite() -> InputError:
    return InputError("q contains NaN or infinity")


def evaluate(model: ChainModel, q, entry, batch, tail: tuple[int, ...]) -> np.ndarray:
    """Run a compiled chain kernel on checked joint values ``q (..., n)``: the single entry
    point ``entry()(address, q, out)`` for one configuration, ``batch(constants, kinds, pitches,
    Q, out)`` into ``out (N, *tail)`` otherwise; shaped ``(..., *tail)``."""
    q = _as_q(model, q)
    d = kernel_data(model)
    if q.ndim == 1:
        out = np.empty(tail)
        if entry()(d.address, q, out):
            out = None
    else:
        Q = np.ascontiguousarray(q.reshape(-1, model.n))
        out = np.empty((Q.shape[0],) + tail)
        bad = batch(d.constants, d.kinds, d.pitches, Q, out)
        out = None if bad else out.reshape(q.shape[:-1] + tail)
    if out is None:
        raise _nonfinite()
    return out


#: the model of the last one-configuration call, its packed chain's address, the compiled entry
#: point and the kernel data (which keep the packed chain alive), in one tuple (one assignment:
#: another thread sees the old tuple or the new one); holding the model keeps its id from being
#: reused. An identity test costs less than the cache's lookup by id.
#: :mod:`kinestat.serial.jacobian` keeps its own.
_last: tuple = (object(), 0.0, None, None)  # matches no argument (not even None)


def one_call(model: ChainModel, entry) -> tuple:
    """The memo tuple of a one-configuration call of ``model`` by ``entry`` (see :data:`_last`);
    builds the model's kernel data if need be."""
    d = kernel_data(model)
    return (model, d.address, entry, d)


_F64 = np.dtype(np.float64)
_ND = np.ndarray
_S44 = (4, 4)
_empty = np.empty


def fk(model: ChainModel, q) -> np.ndarray:
    """End pose(s) ``T_base_end (..., 4, 4)`` for joint values ``q`` of shape ``(..., n)``.

    Also known as the forward analysis (Nadkarni; Vibhute): :func:`forward_analysis` is an
    alias.

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]])  # planar RR
    >>> np.round(fk(arm, [np.pi / 2, 0.0])[:3, 3], 12) + 0.0
    array([0., 2., 0.])
    >>> fk(arm, np.zeros((5, 3, 2))).shape
    (5, 3, 4, 4)
    """
    # the model of the last one-configuration call with q a float64 vector goes straight to the
    # compiled entry point (no per-call type dispatch; it checks q's length and values);
    # anything else, and any error, through the checked path
    last = _last  # read once: another thread may replace it
    if last[0] is model and type(q) is _ND and q.ndim == 1 and q.dtype is _F64:
        out = _empty(_S44)
        if not last[2](last[1], q, out):
            return out
    return _fk_checked(model, q)


def _fk_checked(model: ChainModel, q) -> np.ndarray:
    """:func:`fk` by the checked path; a single configuration's model is remembered."""
    global _last
    out = evaluate(model, q, _fk_entry, kernels().fk_batch, _S44)
    if out.ndim == 2:
        _last = one_call(model, _FK_ONE or _fk_entry())
    return out


#: the theses' name for :func:`fk`
forward_analysis = fk


def iter_fk(
    model: ChainModel, q, chunk_rows: int = CHUNK_ROWS
) -> Iterator[tuple[slice, np.ndarray]]:
    """Stream end poses over a large batch ``q (N, n)`` chunk by chunk: yields
    ``(rows, poses)`` so that 10^7 configurations need only one chunk of output at a time.

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0]])
    >>> [(rows.start, T.shape) for rows, T in iter_fk(arm, np.zeros((5, 1)), chunk_rows=2)]
    [(0, (2, 4, 4)), (2, (2, 4, 4)), (4, (1, 4, 4))]
    """
    q = _as_q(model, q)
    Q = q.reshape(-1, model.n)
    for rows in chunk_slices(Q.shape[0], chunk_rows):
        yield rows, fk(model, Q[rows])


def fk_frames(model: ChainModel, q) -> np.ndarray:
    """Every link frame ``F_i = C0 Z(q1) C1 … Z(qi) Ci`` for i = 0..n, shape ``(..., n+1, 4, 4)``.

    ``F_0 = C0`` is the frame in which joint 1 moves (its z axis is joint 1's axis), ``F_{i-1}``
    the frame of joint i, and ``F_n`` the end pose. For chains built from standard DH (and
    Nadkarni's notation) ``F_i`` is the DH frame x(i).

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    >>> fk_frames(arm, [0.0, 0.0])[:, 0, 3]  # x of the frame origins
    array([0., 1., 2.])
    """
    q = model.check_q(q)
    Z = joint_motion(model, q)
    C = model.constants
    out = np.empty(q.shape[:-1] + (model.n + 1, 4, 4))
    T = np.broadcast_to(C[0], q.shape[:-1] + (4, 4))
    out[..., 0, :, :] = T
    for i in range(model.n):
        T = T @ Z[..., i, :, :] @ C[i + 1]
        out[..., i + 1, :, :] = T
    return out


def joint_axes(model: ChainModel, q) -> tuple[np.ndarray, np.ndarray]:
    """Joint axes as lines in the base frame: unit directions U(i) and feet of perpendicular ρn(i).

    Returns ``(u, rho_n)`` each ``(..., n, 3)``; ρn(i) is the point of axis i nearest the origin
    (Nadkarni's "normal vector to the joint axis from the origin").

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    >>> u, rho = joint_axes(arm, [0.0, 0.0])
    >>> u[1], rho[1]
    (array([0., 0., 1.]), array([1., 0., 0.]))
    """
    F = fk_frames(model, q)[..., :-1, :, :]
    u = F[..., :3, 2]
    p = F[..., :3, 3]
    rho = p - np.sum(p * u, axis=-1, keepdims=True) * u
    return u, rho
