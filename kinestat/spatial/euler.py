"""Euler angles of a rotation: all 12 axis sequences, intrinsic and extrinsic (24 conventions).

SciPy's conventions (:class:`scipy.spatial.transform.Rotation`, written out here in NumPy so
that a command printing one pose does not import SciPy) and its sequence strings: upper case is
intrinsic (rotations about the moving axes, ``"ZYX"``: yaw-pitch-roll), lower case extrinsic
(about the fixed axes, ``"zyx"``). ``matrix_from_euler(a, "ZYX")`` is ``Rz(a0) Ry(a1) Rx(a2)``;
``matrix_from_euler(a, "zyx")`` is ``Rx(a2) Ry(a1) Rz(a0)``.

Gimbal lock: when the middle angle is within :data:`GIMBAL_TOL` of a singular value (0 or pi
for the proper sequences such as ``"ZXZ"``, +-pi/2 for the Tait-Bryan ones such as ``"ZYX"``)
only the sum or difference of the first and third angles is well determined;
:func:`euler_from_matrix` reports those entries with a boolean mask (``return_degenerate=True``).
At the lock itself the third angle is set to 0 and the first carries the whole rotation, like
SciPy. Unlike SciPy's ``as_euler`` (which zeroes the third angle anywhere within 1e-7 rad of the
lock and then misses ``R`` by up to ~1e-7), the angles returned always reproduce ``R`` to
rounding: near but not at the lock they are the generic solution.
"""

from __future__ import annotations

from itertools import product

import numpy as np

from kinestat.errors import InputError
from kinestat.spatial.transforms import as_array

__all__ = [
    "EULER_SEQUENCES",
    "GIMBAL_TOL",
    "check_sequence",
    "is_proper_sequence",
    "matrix_from_euler",
    "euler_from_matrix",
]

#: The 24 conventions: 12 intrinsic (upper case) then the same 12 extrinsic (lower case).
EULER_SEQUENCES: tuple[str, ...] = tuple(
    s
    for case in (str.upper, str.lower)
    for s in (case("".join(p)) for p in product("xyz", repeat=3))
    if s[0] != s[1] and s[1] != s[2]
)

#: Distance (rad) of the middle angle from its singular value below which the decomposition is
#: reported as degenerate (gimbal lock); SciPy's threshold.
GIMBAL_TOL: float = 1e-7

#: Rotation matrices are accepted when ``max|R R^T - I|`` and ``|det R - 1|`` are below this.
ORTHO_TOL: float = 1e-6


def check_sequence(seq: str) -> str:
    """Return ``seq`` if it is one of :data:`EULER_SEQUENCES`, else raise :class:`InputError`.

    >>> check_sequence('ZYX')
    'ZYX'
    """
    if not isinstance(seq, str) or seq not in EULER_SEQUENCES:
        raise InputError(
            f"unknown Euler sequence {seq!r}: use three axes from x, y, z with no two consecutive "
            "equal, all upper case for intrinsic (e.g. 'ZYX', 'ZXZ') or all lower case for "
            "extrinsic (e.g. 'xyz')"
        )
    return seq


def is_proper_sequence(seq: str) -> bool:
    """True for the proper (symmetric) Euler sequences such as ``ZXZ``; False for Tait-Bryan.

    >>> is_proper_sequence('ZXZ'), is_proper_sequence('ZYX')
    (True, False)
    """
    return check_sequence(seq)[0].lower() == seq[2].lower()


def matrix_from_euler(angles, seq: str, *, degrees: bool = False) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` from Euler angles ``(..., 3)`` in sequence ``seq``.

    Lecture notes (Euler angles of the end effector); composition as in SciPy's ``from_euler``.

    >>> np.round(matrix_from_euler([90.0, 0.0, 0.0], 'ZYX', degrees=True), 12) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    check_sequence(seq)
    a = as_array(angles, shape_tail=(3,), name="Euler angles")
    flat = np.radians(a.reshape(-1, 3)) if degrees else a.reshape(-1, 3)
    return _compose(flat, seq).reshape(a.shape[:-1] + (3, 3))


def _elementary(axis: int, t: np.ndarray) -> np.ndarray:
    """Rotations ``(N, 3, 3)`` by angles ``t (N,)`` about base axis 0, 1 or 2."""
    c, s = np.cos(t), np.sin(t)
    R = np.zeros(t.shape + (3, 3))
    i, j = (axis + 1) % 3, (axis + 2) % 3
    R[:, axis, axis] = 1.0
    R[:, i, i] = c
    R[:, j, j] = c
    R[:, j, i] = s
    R[:, i, j] = -s
    return R


def _compose(a: np.ndarray, seq: str) -> np.ndarray:
    """``R (N, 3, 3)`` of angles ``a (N, 3)``: intrinsic ``R1 R2 R3``, extrinsic ``R3 R2 R1``."""
    Rs = [_elementary(_AXIS[c.lower()], a[:, n]) for n, c in enumerate(seq)]
    return Rs[0] @ Rs[1] @ Rs[2] if seq.isupper() else Rs[2] @ Rs[1] @ Rs[0]


def _quat_from_matrix(R: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(N, 4)`` (scalar last) of rotations ``(N, 3, 3)``: Shepperd's method
    (the largest of the trace and the diagonal picks the component computed by a square root,
    as SciPy's ``from_matrix``), then normalised."""
    d = np.stack([R[:, 0, 0], R[:, 1, 1], R[:, 2, 2], R[:, 0, 0] + R[:, 1, 1] + R[:, 2, 2]], -1)
    pick = np.argmax(d, axis=-1)
    q = np.empty((len(R), 4))
    for i in range(3):  # a diagonal entry is largest: component i by the square root
        n = pick == i
        j, k = (i + 1) % 3, (i + 2) % 3
        Rn = R[n]
        q[n, i] = 1.0 - d[n, 3] + 2.0 * d[n, i]
        q[n, j] = Rn[:, j, i] + Rn[:, i, j]
        q[n, k] = Rn[:, k, i] + Rn[:, i, k]
        q[n, 3] = Rn[:, k, j] - Rn[:, j, k]
    n = pick == 3
    Rn = R[n]
    q[n, 0] = Rn[:, 2, 1] - Rn[:, 1, 2]
    q[n, 1] = Rn[:, 0, 2] - Rn[:, 2, 0]
    q[n, 2] = Rn[:, 1, 0] - Rn[:, 0, 1]
    q[n, 3] = 1.0 + d[n, 3]
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _check_rotations(R: np.ndarray, tol: float) -> None:
    err_o = np.max(np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)), axis=(-1, -2))
    err_d = np.abs(np.linalg.det(R) - 1.0)
    bad = (err_o > tol) | (err_d > tol)
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f" at batch index {idx}" if R.ndim > 2 else ""
        raise InputError(
            f"R{where} is not a rotation matrix (max|R R^T - I| = {err_o[bad].flat[0]:.3g}, "
            f"det = {np.linalg.det(R)[bad].flat[0]:.6g}); pass an orthonormal matrix with "
            f"determinant +1 (tolerance {tol:g})"
        )


_AXIS = {"x": 0, "y": 1, "z": 2}


def _wrap(a: np.ndarray) -> np.ndarray:
    """Angles into (-pi, pi]."""
    return np.pi - np.mod(np.pi - a, 2 * np.pi)


def _angles_from_quat(quat: np.ndarray, seq: str) -> tuple[np.ndarray, np.ndarray]:
    """Euler angles ``(N, 3)`` from unit quaternions ``(N, 4)`` (scalar last) with the direct
    method of Bernardes & Viollet (PLoS ONE 17(11), 2022), the one SciPy uses, but without SciPy's
    gimbal-lock override, so the angles reproduce the rotation everywhere. Also returns the
    middle angle's distance from its singular value."""
    extrinsic = seq.islower()
    axes = seq.lower() if extrinsic else seq.lower()[::-1]
    i, j, k = (_AXIS[c] for c in axes)
    proper = i == k
    if proper:
        k = 3 - i - j
    sign = (i - j) * (j - k) * (k - i) // 2
    x, w = quat[:, :3], quat[:, 3]
    if proper:
        a, b, c, d = w, x[:, i], x[:, j], sign * x[:, k]
    else:
        a, b, c, d = w - x[:, j], x[:, i] + sign * x[:, k], x[:, j] + w, sign * x[:, k] - x[:, i]
    mid = 2.0 * np.arctan2(np.hypot(c, d), np.hypot(a, b))  # in [0, pi]
    half_sum, half_diff = np.arctan2(b, a), np.arctan2(d, c)
    first, third = half_sum - half_diff, half_sum + half_diff
    distance = np.minimum(mid, np.pi - mid)
    if not proper:
        third = sign * third
        mid = mid - np.pi / 2
    ang = np.stack([_wrap(first), mid, _wrap(third)], axis=-1)
    return (ang if extrinsic else ang[:, ::-1]), distance


def _zero_third(R: np.ndarray, ang: np.ndarray, seq: str) -> np.ndarray:
    """At gimbal lock, move the third angle into the first (``first +- third``, whichever sign
    reproduces ``R``) where the result still reproduces ``R`` to 1e-12; else keep ``ang``."""
    best, err_best = ang, np.full(len(ang), np.inf)
    for sgn in (1.0, -1.0):
        cand = np.stack([_wrap(ang[:, 0] + sgn * ang[:, 2]), ang[:, 1], np.zeros(len(ang))], -1)
        err = np.max(np.abs(_compose(cand, seq) - R), axis=(-1, -2))
        take = err < err_best
        best = np.where(take[:, None], cand, best)
        err_best = np.where(take, err, err_best)
    return np.where((err_best <= 1e-12)[:, None], best, ang)


def euler_from_matrix(
    R,
    seq: str,
    *,
    degrees: bool = False,
    return_degenerate: bool = False,
    tol: float = ORTHO_TOL,
):
    """Euler angles ``(..., 3)`` of rotation matrices ``(..., 3, 3)`` in sequence ``seq``.

    Ranges (SciPy's): first and third angles in (-pi, pi]; the middle one in [0, pi] for proper
    sequences and [-pi/2, pi/2] for Tait-Bryan ones. With ``return_degenerate=True`` returns
    ``(angles, degenerate)`` where ``degenerate`` ``(...)`` marks gimbal lock (middle angle within
    :data:`GIMBAL_TOL` of its singular value: only the sum or difference of the first and third
    angles is determined). At the lock itself the third angle is 0 and the first carries the
    whole rotation about the aligned axes; the angles always reproduce ``R`` to rounding.

    Raises :class:`InputError` for an unknown sequence, a NaN, or a matrix that is not a rotation
    within ``tol``.

    >>> R = matrix_from_euler([30.0, 20.0, 10.0], 'ZYX', degrees=True)
    >>> np.round(euler_from_matrix(R, 'ZYX', degrees=True), 9)
    array([30., 20., 10.])
    """
    check_sequence(seq)
    R = as_array(R, shape_tail=(3, 3), name="R")
    _check_rotations(R, tol)
    flat = R.reshape(-1, 3, 3)
    ang, distance = _angles_from_quat(_quat_from_matrix(flat), seq)
    degenerate = distance <= GIMBAL_TOL
    if np.any(degenerate):
        ang[degenerate] = _zero_third(flat[degenerate], ang[degenerate], seq)
    if degrees:
        ang = np.degrees(ang)
    angles = ang.reshape(R.shape[:-2] + (3,))
    if return_degenerate:
        return angles, degenerate.reshape(R.shape[:-2])
    return angles
