"""Input validation of spatial quantities — the one place for it (issue 10, item 2).

Each validator converts to a float64 array, checks shape and finiteness and the property that
makes the value what its name says (a rigid pose, a unit vector), and raises one clear line
naming the argument: :class:`~kinestat.errors.InputError` by default, or the error class the
caller passes (``ModelError`` for data that is part of a model).
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.errors import InputError
from kinestat.spatial.tolerances import LAST_ROW_TOL, ORTHO_TOL, UNIT_TOL
from kinestat.spatial.transforms import as_array

__all__ = ["as_array", "as_count", "as_number", "as_pose", "as_rotation", "as_vector3",
           "as_unit_vector", "batch_index", "frozen", "freeze_fields"]

_LAST_ROW = np.array([0.0, 0.0, 0.0, 1.0])


def batch_index(mask: np.ndarray) -> str:
    """``" at batch index (i, j)"`` for the first True entry of ``mask`` ("" for a scalar).

    >>> batch_index(np.array([False, True])), batch_index(np.array(True))
    (' at batch index (1,)', '')
    """
    if mask.ndim == 0:
        return ""
    return f" at batch index {tuple(int(i) for i in np.argwhere(mask)[0])}"


def _pose_index(mask: np.ndarray) -> str:
    """``" (pose (i, j))"`` for the first True entry of ``mask`` ("" for one pose)."""
    if mask.ndim == 0:
        return ""
    return f" (pose {tuple(int(i) for i in np.argwhere(mask)[0])})"


def _one_pose_clear(rows: list, tol: float, last_row_tol: float) -> bool:
    """True when ONE pose (its rows as lists) passes :func:`as_pose`'s checks by half their
    tolerances or more, in scalars (a control cycle validates a pose every cycle); False sends
    it through the full checks, which decide and say what is wrong."""
    (a, b, c, _), (d, e, f, _), (g, h, i, _), last = rows
    if not all(map(math.isfinite, (*rows[0], *rows[1], *rows[2], *last))):
        return False
    ortho = max(abs(a * a + b * b + c * c - 1.0), abs(d * d + e * e + f * f - 1.0),
                abs(g * g + h * h + i * i - 1.0), abs(a * d + b * e + c * f),
                abs(a * g + b * h + c * i), abs(d * g + e * h + f * i))
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    row = max(abs(last[0]), abs(last[1]), abs(last[2]), abs(last[3] - 1.0))
    return ortho <= 0.5 * tol and abs(det - 1.0) <= 0.5 * tol and row <= 0.5 * last_row_tol


def as_pose(T, name: str = "pose", *, tol: float = ORTHO_TOL,
            last_row_tol: float = LAST_ROW_TOL, single: bool = False,
            error: type[Exception] = InputError) -> np.ndarray:
    """Rigid poses ``(..., 4, 4)`` (``(4, 4)`` when ``single``), checked.

    Checks, in this order: numbers of shape ``(..., 4, 4)``; finite; rotation part orthonormal
    with determinant +1 to ``tol``; last row ``[0, 0, 0, 1]`` to ``last_row_tol``. Raises
    ``error`` naming ``name`` (and the first offending pose's batch index).

    >>> as_pose(np.eye(4), "T_base_tool").shape
    (4, 4)
    >>> as_pose(2 * np.eye(4), "T_base_tool")
    Traceback (most recent call last):
    ...
    kinestat.errors.InputError: T_base_tool is not a rigid pose: its rotation part is not \
orthonormal with determinant +1 (max|R Rᵀ − I| = 3, det = 8, tolerance 1e-06)
    """
    try:
        T = np.asarray(T, dtype=float)
    except (TypeError, ValueError) as exc:
        raise error(f"{name} must be a 4x4 homogeneous transform of numbers: {exc}") from exc
    if T.shape == (4, 4) and _one_pose_clear(T.tolist(), tol, last_row_tol):
        return T
    if (T.shape != (4, 4)) if single else (T.ndim < 2 or T.shape[-2:] != (4, 4)):
        want = "(4, 4)" if single else "(..., 4, 4)"
        raise error(f"{name} must be a 4x4 homogeneous transform of shape {want}, "
                    f"got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        raise error(f"{name} contains NaN or infinity")
    _check_rotation(T[..., :3, :3], name, " is not a rigid pose: its rotation part", tol, error)
    bottom = np.max(np.abs(T[..., 3, :] - _LAST_ROW), axis=-1, initial=0.0)
    bad = bottom > last_row_tol
    if np.any(bad):
        raise error(f"{name}{_pose_index(bad)} is not a rigid pose: the last row of a pose must "
                    "be [0, 0, 0, 1]")
    return T


def _check_rotation(R: np.ndarray, name: str, what: str, tol: float,
                    error: type[Exception]) -> None:
    """Raise ``error`` when some finite ``R (..., 3, 3)`` is not orthonormal with det +1 to
    ``tol``; the message starts with ``name``, the batch index, then ``what``."""
    ortho = np.max(np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)), axis=(-1, -2), initial=0.0)
    det = np.linalg.det(R) if R.size else np.ones(R.shape[:-2])
    bad = (ortho > tol) | (np.abs(det - 1.0) > tol)
    if np.any(bad):
        raise error(
            f"{name}{_pose_index(bad)}{what} is not orthonormal with determinant +1 "
            f"(max|R Rᵀ − I| = {ortho[bad].flat[0]:.3g}, det = {det[bad].flat[0]:.6g}, "
            f"tolerance {tol:g})"
        )


def as_rotation(R, name: str = "rotation", *, tol: float = ORTHO_TOL,
                error: type[Exception] = InputError) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)``, checked: numbers of that shape, finite, orthonormal
    with determinant +1 to ``tol``. Raises ``error`` naming ``name`` (and the first offending
    matrix's batch index).

    >>> as_rotation(np.eye(3), "R_base_tool").shape
    (3, 3)
    >>> as_rotation(-np.eye(3), "R_base_tool")
    Traceback (most recent call last):
    ...
    kinestat.errors.InputError: R_base_tool is not orthonormal with determinant +1 \
(max|R Rᵀ − I| = 0, det = -1, tolerance 1e-06)
    """
    try:
        R = np.asarray(R, dtype=float)
    except (TypeError, ValueError) as exc:
        raise error(f"{name} must be 3x3 rotation matrices of numbers: {exc}") from exc
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise error(f"{name} must be rotation matrices of shape (..., 3, 3), got shape {R.shape}")
    if not np.all(np.isfinite(R)):
        raise error(f"{name} contains NaN or infinity")
    _check_rotation(R, name, "", tol, error)
    return R


def as_number(value, name: str, *, positive: bool = False, nonnegative: bool = False,
              error: type[Exception] = InputError) -> float:
    """One finite real number (a tolerance, a length), as a float; ``positive``: > 0 too,
    ``nonnegative``: ≥ 0 too.

    >>> as_number(1e-9, "tol", positive=True)
    1e-09
    >>> as_number(float("nan"), "tol")
    Traceback (most recent call last):
    ...
    kinestat.errors.InputError: tol must be a finite number, got nan
    """
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise error(f"{name} must be a number, got {value!r}") from None
    if isinstance(value, (bool, np.bool_)) or not math.isfinite(x):
        raise error(f"{name} must be a finite number, got {value!r}")
    if positive and not x > 0.0:
        raise error(f"{name} must be positive, got {value!r}")
    if nonnegative and not x >= 0.0:
        raise error(f"{name} must be ≥ 0, got {value!r}")
    return x


def as_count(value, name: str, *, minimum: int = 0,
             error: type[Exception] = InputError) -> int:
    """A whole number ≥ ``minimum`` (an iteration budget, a number of steps), as an int.

    >>> as_count(4, "polish")
    4
    >>> as_count(2.5, "polish")
    Traceback (most recent call last):
    ...
    kinestat.errors.InputError: polish must be a whole number ≥ 0, got 2.5
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) \
            or value < minimum:
        shown = repr(value) if len(repr(value)) <= 40 else "a very long value"
        raise error(f"{name} must be a whole number ≥ {minimum}, got {shown}")
    return int(value)


def as_vector3(v, name: str = "vector", *, single: bool = False,
               error: type[Exception] = InputError) -> np.ndarray:
    """Finite 3-vectors ``(..., 3)`` (exactly ``(3,)`` when ``single``).

    >>> as_vector3([1, 2, 3], "p_base_tool")
    array([1., 2., 3.])
    """
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError) as exc:
        raise error(f"{name} must be 3 numbers: {exc}") from exc
    if (a.shape != (3,)) if single else (a.ndim == 0 or a.shape[-1] != 3):
        raise error(f"{name} must have shape {'(3,)' if single else '(..., 3)'}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise error(f"{name} contains NaN or infinity")
    return a


def as_unit_vector(u, name: str = "direction", *, tol: float = UNIT_TOL,
                   normalize: bool = False, single: bool = False,
                   error: type[Exception] = InputError) -> np.ndarray:
    """Unit vectors ``(..., 3)``: ``||u| − 1| <= tol`` is required; with ``normalize`` any
    nonzero vector is accepted and scaled to unit length (``u / |u|``).

    >>> as_unit_vector([0.0, 0.0, 1.0], "z_base_tool")
    array([0., 0., 1.])
    >>> as_unit_vector([0.0, 3.0, 4.0], "s", normalize=True)
    array([0. , 0.6, 0.8])
    >>> as_unit_vector([0.0, 0.0, 0.0], "s", normalize=True)
    Traceback (most recent call last):
    ...
    kinestat.errors.InputError: s is the zero vector: give a nonzero direction
    """
    a = as_vector3(u, name, single=single, error=error)
    norm = np.linalg.norm(a, axis=-1)
    if normalize:
        bad = norm == 0.0
        if np.any(bad):
            raise error(f"{name} is the zero vector{batch_index(bad)}: give a nonzero direction")
        return a / norm[..., None]
    bad = np.abs(norm - 1.0) > tol
    if np.any(bad):
        dev = float(np.abs(norm - 1.0)[bad].flat[0])
        raise error(f"{name}{batch_index(bad)} must be a unit vector: its length differs from 1 "
                    f"by {dev:.3g} (tolerance {tol:g})")
    return a


def frozen(a, dtype=None) -> np.ndarray:
    """A read-only copy of ``a`` (as ``dtype`` when given): the arrays held by immutable models.

    >>> f = frozen([1, 2], float)
    >>> f, f.flags.writeable
    (array([1., 2.]), False)
    """
    out = np.array(a, dtype=dtype, copy=True)
    out.setflags(write=False)
    return out


def freeze_fields(obj, names) -> None:
    """Replace the attributes ``names`` of a frozen dataclass instance ``obj`` by read-only
    copies (:func:`frozen`), from its ``__post_init__``."""
    for name in names:
        object.__setattr__(obj, name, frozen(getattr(obj, name)))
