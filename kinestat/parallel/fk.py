"""Forward kinematics of the platform: every assembly mode, tracking mode, general 6-6.

* :func:`fk_all` — the special 6-6 (Griffis–Duffy) platform reduced to its equivalent 3-3
  (:func:`reduce_to_33`) and solved in closed form (:mod:`kinestat.parallel.fk33`): every real
  assembly mode, each polished by Newton steps on the six real legs and verified by reverse
  kinematics. Batched: lengths (..., 6) → poses (..., 16, 4, 4) and a validity mask.
* :func:`fk_tracking` — the mode continuous with a previous pose (Newton from it), checked.
* :func:`fk_numeric` — Newton from a guess; works for any 6-6 platform, special or not.

The reduction (Vibhute 2011 §2.1.1, after Griffis & Duffy's patent): an edge point X of an edge
AB with ``X = A + t (B − A)`` is, for any point P, at squared distance
``|PX|² = (1 − t)|PA|² + t|PB|² − t(1 − t)|AB|²`` (Stewart's theorem). Each of the six legs
joins a corner to an edge point of the other triangle, so its squared length is a combination of
two squared equivalent-3-3 lengths: six linear equations in the six unknown squares, with
determinant ``Π(1 − t) − Π t`` — zero for an architecturally singular layout.
"""

from __future__ import annotations

import math
import warnings
import weakref
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import numpy as np

from kinestat.errors import InputError, ModelError, SingularityError, UnreachableError
from kinestat.parallel import _fk_kernels
from kinestat.parallel._refine import apply_twist, leg_residual, refine_where
from kinestat.parallel.fk33 import (
    _W,
    _X,
    MAX_SOLUTIONS,
    _fk33_modes,
    assemble_modes,
    first_occurrences,
    mirror_matrices,
    pose_signature,
    triangle_frame,
)
from kinestat.parallel.legs import as_pose
from kinestat.parallel.platform import Platform, SpecialLayout
from kinestat.spatial.transforms import as_array
from kinestat.spatial.validate import as_count, as_number

__all__ = [
    "FKSolutions",
    "reduction_matrix",
    "reduce_to_33",
    "fk_all",
    "fk_list",
    "fk_numeric",
    "fk_tracking",
    "check_lengths",
]

# For each role O, P, Q, R, S, T: (unknown index with weight 1 − t, unknown index with weight t)
# over the 3-3 unknowns [or, os, ps, pt, qt, qr]; and the edge (corner roles) the point lies on.
_ROLE_TERMS = {0: (0, 1), 1: (2, 3), 2: (4, 5), 3: (5, 0), 4: (1, 2), 5: (3, 4)}
_ROLE_EDGE = {0: ("top", 3, 4), 1: ("top", 4, 5), 2: ("top", 5, 3),
              3: ("base", 2, 0), 4: ("base", 0, 1), 5: ("base", 1, 2)}


@dataclass(frozen=True)
class FKSolutions:
    """Assembly modes of a batch of leg-length sets.

    Attributes:
        poses: (..., 16, 4, 4) top frame relative to the base frame (NaN where not valid).
        valid: (..., 16) True where the slot holds a verified, distinct real assembly mode.
        residual: (..., 16) largest leg-length error of each slot's pose (reverse kinematics;
            inf where not valid).

    Valid modes fill the slots from the front in mirror pairs: slot ``2i + 1`` holds the
    mirror image through the base plane of the mode in slot ``2i`` (a mode lying in the base
    plane is its own mirror image and appears once).
    """

    poses: np.ndarray
    valid: np.ndarray
    residual: np.ndarray

    @property
    def count(self) -> np.ndarray:
        """Number of valid modes per leg-length set, shape (...)."""
        return self.valid.sum(axis=-1)


def check_lengths(lengths, name: str = "leg lengths") -> np.ndarray:
    """Leg lengths (..., 6) as floats: finite and positive, else InputError."""
    L = as_array(lengths, shape_tail=(6,), name=name)
    if np.any(L <= 0):
        bad = np.argwhere(L <= 0)[0]
        raise InputError(f"{name} must be positive, got {L[tuple(bad)]:g} at index "
                         f"{tuple(int(i) for i in bad)}")
    return L


def _layout(platform: Platform) -> SpecialLayout:
    lay = platform.layout
    if lay is None:
        raise ModelError(
            f"platform {platform.name!r} is not a special 6-6 (no three base points on the "
            "edges of the triangle of the other three, matched with the top): the closed-form "
            "all-mode FK does not apply; use fk_numeric (Newton from a guess)")
    return lay


def reduction_matrix(platform: Platform) -> tuple[np.ndarray, np.ndarray]:
    """(M, c) with ``M @ u = L²[roles] + c``, u the squared 3-3 lengths [or, os, ps, pt, qt, qr].

    Rows follow the roles O, P, Q, R, S, T (model legs ``layout.order``).
    """
    lay = _layout(platform)
    base = platform.base_points[list(lay.order)]
    top = platform.top_points[list(lay.order)]
    M = np.zeros((6, 6))
    c = np.zeros(6)
    for role, (i, j) in _ROLE_TERMS.items():
        t = lay.t[role]
        M[role, i] += 1.0 - t
        M[role, j] += t
        side, a, b = _ROLE_EDGE[role]
        pts = top if side == "top" else base
        c[role] = t * (1.0 - t) * float(np.sum((pts[a] - pts[b]) ** 2))
    return M, c


@lru_cache(maxsize=64)
def _reduction(platform: Platform) -> tuple[list[int], np.ndarray, np.ndarray]:
    lay = _layout(platform)
    M, c = reduction_matrix(platform)
    return list(lay.order), np.linalg.inv(M).T, c


def _reduce_sq(platform: Platform, L: np.ndarray) -> np.ndarray:
    order, MinvT, c = _reduction(platform)
    # absurd lengths (1e300) overflow to inf/nan here; callers report them as unreachable
    with np.errstate(over="ignore", invalid="ignore"):
        return (L[..., order] ** 2 + c) @ MinvT


def reduce_to_33(platform: Platform, lengths) -> np.ndarray:
    """Equivalent 3-3 leg lengths ``[or, os, ps, pt, qt, qr]`` (..., 6) of a special 6-6.

    Vibhute 2011 §2.1.1 (``solve_georedux``). NaN where a squared length comes out negative
    (those leg lengths have no real assembly).
    """
    L = check_lengths(lengths)
    sq = _reduce_sq(platform, L)
    return np.where(sq >= 0, np.sqrt(np.abs(sq)), np.nan)


def _pose_distance(a: np.ndarray, b: np.ndarray, scale: float) -> np.ndarray:
    """A dimensionless distance between poses: max rotation-entry and translation/scale diffs."""
    dr = np.abs(a[..., :3, :3] - b[..., :3, :3]).max(axis=(-1, -2))
    dp = np.abs(a[..., :3, 3] - b[..., :3, 3]).max(axis=-1) / scale
    return np.maximum(dr, dp)


Backend = Literal["numba", "numpy"]

_KERNEL_CONSTANTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _kernel_constants(platform: Platform) -> tuple:
    """The compiled kernels' constant arguments for a special 6-6 platform, cached per platform
    outside the (immutable) platform."""
    got = _KERNEL_CONSTANTS.get(platform)
    if got is not None:
        return got
    lay = _layout(platform)
    order = np.array(lay.order, dtype=np.int64)
    M, c = reduction_matrix(platform)
    minvt = np.ascontiguousarray(np.linalg.inv(M).T)
    base_tri = platform.base_points[order[:3]]
    top_tri = platform.top_points[order[3:]]
    Fb = triangle_frame(base_tri)
    Ft = triangle_frame(top_tri)
    Ft_inv = np.linalg.inv(Ft)
    scale = float(np.linalg.norm(base_tri[1] - base_tri[0]))
    base_loc = (base_tri - Fb[:3, 3]) @ Fb[:3, :3] / scale
    top_loc = (top_tri - Ft[:3, 3]) @ Ft[:3, :3] / scale
    sides2 = np.array([np.sum((top_loc[i] - top_loc[j]) ** 2)
                       for i, j in ((0, 1), (1, 2), (2, 0))])
    O, Pp, Q = base_loc
    # circles of R (about OQ, toward P), S (about OP, toward Q), T (about PQ, toward O), with
    # the indices of their squared lengths in [or, os, ps, pt, qt, qr]
    G = np.zeros((3, 12))
    for i, (a, b, third, ia, ib) in enumerate(((O, Q, Pp, 0, 5), (O, Pp, Q, 1, 2),
                                               (Pp, Q, O, 3, 4))):
        e = b - a
        d = np.linalg.norm(e)
        e = e / d
        n = (third - a) - ((third - a) @ e) * e
        n = n / np.linalg.norm(n)
        G[i, 0:3], G[i, 3:6], G[i, 6:9] = a, e, n
        G[i, 9], G[i, 10], G[i, 11] = d, ia, ib
    Mb, Mt = mirror_matrices(base_tri, top_tri)
    got = (G, sides2, scale, minvt, np.ascontiguousarray(c), order,
           np.ascontiguousarray(_W), np.ascontiguousarray(_X), np.ascontiguousarray(Fb),
           np.ascontiguousarray(Ft_inv), np.ascontiguousarray(Mb), np.ascontiguousarray(Mt),
           np.ascontiguousarray(platform.base_points), np.ascontiguousarray(platform.top_points))
    _KERNEL_CONSTANTS[platform] = got
    return got


def fk_all(platform: Platform, lengths, *, tol: float = 1e-9, polish: int = 4,
           backend: Backend = "numba") -> FKSolutions:
    """Every real assembly mode of a special 6-6 platform, batched over leg-length sets.

    Args:
        platform: a special 6-6 platform (:attr:`Platform.layout` not None).
        lengths: (..., 6) leg lengths in the model's leg order.
        tol: a mode is valid when reverse kinematics reproduces every leg within ``tol``
            (model length unit).
        polish: at most this many Newton steps on the six real legs, for closed-form poses
            whose legs are off by more than ``tol / 10``.
        backend: deprecated, for the tests: ``"numba"`` (the default; the compiled kernels of
            :mod:`kinestat.parallel._fk_kernels`) or ``"numpy"`` (the private NumPy reference).
            Both find the same modes (the order of the pairs may differ).

    Returns:
        :class:`FKSolutions` with up to 16 modes per set (mirror pairs in slots 2i, 2i+1).
    """
    if backend == "numpy":
        return _fk_all_reference(platform, lengths, tol=tol, polish=polish)
    if backend != "numba":
        raise InputError(f"backend must be 'numba' or 'numpy', got {backend!r}")
    L = check_lengths(lengths)
    tol, polish = as_number(tol, "tol", positive=True), as_count(polish, "polish")
    _layout(platform)
    shape = L.shape[:-1]
    poses, valid, res = _fk_kernels.fk_all_arrays(_kernel_constants(platform),
                                                  L.reshape(-1, 6), tol, polish)
    n = poses.shape[1]
    return FKSolutions(poses=poses.reshape(shape + (n, 4, 4)), valid=valid.reshape(shape + (n,)),
                       residual=res.reshape(shape + (n,)))


def _fk_all_reference(platform: Platform, lengths, *, tol: float = 1e-9,
                      polish: int = 4) -> FKSolutions:
    """The NumPy reference of :func:`fk_all` (for the tests): the closed-form 3-3 modes of
    :mod:`kinestat.parallel.fk33`, polished and verified on the six real legs."""
    L = check_lengths(lengths)
    lay = _layout(platform)
    sq = _reduce_sq(platform, L)
    base_tri = platform.base_points[list(lay.order[:3])]
    top_tri = platform.top_points[list(lay.order[3:])]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        bi, qi, pose = _fk33_modes(base_tri, top_tri, sq)
        Lf = L.reshape(-1, 6)[bi]
        pose, err = refine_where(platform.base_points, platform.top_points, Lf, pose,
                                 np.ones(len(bi), bool), 0.1 * tol, iterations=polish)
        poses, valid, res = assemble_modes(L.shape[:-1], bi, qi, pose, err, tol, base_tri,
                                           top_tri, platform.scale)
        # the mirror images are exact for coplanar joints; check (and polish) them on the real
        # legs anyway, for layouts that are special only to within the detection tolerance
        mirrors = valid.copy()
        mirrors[..., ::2] = False
        poses, err_m = refine_where(platform.base_points, platform.top_points, L[..., None, :],
                                    poses, mirrors, 0.1 * tol, iterations=polish)
    res = np.where(mirrors, err_m, res)
    valid &= ~mirrors | (err_m <= tol)
    valid = first_occurrences(pose_signature(poses, platform.scale), valid)
    poses[~valid] = np.nan
    res[~valid] = np.inf
    return FKSolutions(poses=poses, valid=valid, residual=res)


def _mode_sort_key(platform: Platform, pose: np.ndarray) -> tuple[bool, float]:
    above = pose[2, 3] >= 0
    return (not bool(above), float(_pose_distance(pose, platform.home_pose, platform.scale)))


def fk_list(platform: Platform, lengths, *, tol: float = 1e-9) -> list[np.ndarray]:
    """The assembly modes of one leg-length set as a list of (4, 4) poses.

    Sorted: modes with the top frame's origin above the base plane first, then by closeness to
    the home pose (so the first is the physically assembled prototype's mode near home).

    Raises:
        UnreachableError: the lengths admit no real assembly.
    """
    L = check_lengths(lengths)
    if L.shape != (6,):
        raise InputError(f"fk_list takes one set of 6 leg lengths, got shape {L.shape}; "
                         "use fk_all for batches")
    sol = fk_all(platform, L, tol=tol)
    modes = [sol.poses[i] for i in range(MAX_SOLUTIONS) if sol.valid[i]]
    if not modes:
        sq = _reduce_sq(platform, L)
        why = (" (the equivalent 3-3 has a negative squared leg length)" if np.any(sq < 0)
               else "")
        raise UnreachableError(
            f"leg lengths {np.round(L, 6).tolist()} admit no real assembly of platform "
            f"{platform.name!r}{why}; check the lengths (order {list(platform.leg_names)}, "
            f"free lengths {np.round(platform.free_lengths, 3).tolist()})")
    modes.sort(key=lambda T: _mode_sort_key(platform, T))
    return modes


def _line_det(platform: Platform, pose: np.ndarray) -> np.ndarray:
    _, J = leg_residual(platform.base_points, platform.top_points, 0.0, pose)
    return np.linalg.det(J)


def _newton(platform: Platform, L: np.ndarray, guess: np.ndarray, tol: float, max_iter: int):
    """Damped Newton with bounded steps; returns (pose, residual, det signs seen (…, iters+1))."""
    pose = guess
    s = platform.scale
    signs = [np.sign(_line_det(platform, pose))]
    for _ in range(max_iter):
        r, J = leg_residual(platform.base_points, platform.top_points, L, pose)
        if np.all(np.abs(r).max(axis=-1) <= tol * 1e-3):
            break
        JtJ = np.swapaxes(J, -1, -2) @ J
        lam = 1e-12 * np.trace(JtJ, axis1=-2, axis2=-1)[..., None, None] + 1e-300
        step = -np.linalg.solve(JtJ + lam * np.eye(6), np.swapaxes(J, -1, -2) @ r[..., None])
        step = step[..., 0]
        # at most 0.2 rad of rotation and 0.2 * scale of translation per step
        fr = np.linalg.norm(step[..., :3], axis=-1) / 0.2
        ft = np.linalg.norm(step[..., 3:], axis=-1) / (0.2 * s)
        f = np.maximum(1.0, np.maximum(fr, ft))
        step = np.where(np.isfinite(step), step / f[..., None], 0.0)
        pose = apply_twist(pose, step)
        signs.append(np.sign(_line_det(platform, pose)))
    r, _ = leg_residual(platform.base_points, platform.top_points, L, pose)
    return pose, np.abs(r).max(axis=-1), np.stack(signs, axis=-1)


def fk_numeric(platform: Platform, lengths, guess=None, *, tol: float = 1e-9,
               max_iter: int = 50) -> np.ndarray:
    """Forward kinematics by Newton's method from ``guess`` (default: home); any 6-6 platform.

    Returns the pose(s) (..., 4, 4) the iteration converges to — one assembly mode, usually
    the one nearest the guess.

    Raises:
        UnreachableError: Newton did not reproduce the legs within ``tol`` (no nearby assembly,
            or a singular configuration on the way); the message names the batch index.
    """
    L = check_lengths(lengths)
    tol, max_iter = as_number(tol, "tol", positive=True), as_count(max_iter, "max_iter")
    g = platform.home_pose if guess is None else as_pose(guess, "guess")
    g = np.broadcast_to(g, L.shape[:-1] + (4, 4)).copy()
    pose, res, _ = _newton(platform, L, g, tol, max_iter)
    bad = ~(res <= tol)
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(np.atleast_1d(bad))[0])
        worst = float(np.nanmax(np.where(bad, res, 0.0)))
        raise UnreachableError(
            f"numerical forward kinematics did not converge{'' if L.ndim == 1 else f' at {idx}'}"
            f" (leg error {worst:.3g} {platform.length_unit} after {max_iter} iterations): the "
            "lengths may admit no assembly near the guess; try another guess (or fk_all, for a "
            "special 6-6 platform)")
    return pose


def fk_tracking(platform: Platform, lengths, previous_pose, *, tol: float = 1e-9,
                max_iter: int = 20, verify: bool | None = None,
                backend: Backend | None = None) -> np.ndarray:
    """The assembly mode continuous with ``previous_pose`` (Newton from it), checked.

    Checks that the iteration converged and that the determinant of the line Jacobian kept its
    sign at every iterate (no singular configuration was crossed). With ``verify`` (default:
    True for a special 6-6) it also solves all modes and checks that the result is the mode
    nearest the previous pose.

    The Newton iteration runs compiled over the batch
    (:func:`kinestat.parallel._fk_kernels.track_kernel`, the steps solved by L D Lᵀ). It decides
    only the clear cases: where any pose fails to converge or the determinant's sign changes
    or comes within 1e-9 (relative) of zero, the whole batch is re-run by the NumPy iteration
    (``_newton``), which decides and names the failure.

    ``backend`` is deprecated (a :class:`DeprecationWarning`; it served the control cycle's
    compute-time work, which is retired): leave it out. ``"numpy"`` still runs the NumPy
    iteration alone until the argument is removed.

    Raises:
        UnreachableError: no convergence.
        SingularityError: the path crossed a singularity or landed in another mode; the
            assembly mode is ambiguous — re-initialise from :func:`fk_list`.
    """
    if backend is not None:
        warnings.warn("fk_tracking(backend=...) is deprecated and will be removed: leave the "
                      "argument out (the compiled iteration runs, with the NumPy iteration "
                      "deciding the unclear cases)", DeprecationWarning, stacklevel=2)
        if backend not in ("numba", "numpy"):
            raise InputError(f"backend must be 'numba' or 'numpy', got {backend!r}")
    else:
        backend = "numba"
    L = check_lengths(lengths)
    tol, max_iter = as_number(tol, "tol", positive=True), as_count(max_iter, "max_iter")
    prev = as_pose(previous_pose, "previous_pose")
    prev = np.broadcast_to(prev, L.shape[:-1] + (4, 4)).copy()
    pose = (_fk_kernels.track_arrays(platform.base_points, platform.top_points, L, prev, tol,
                                     max_iter, platform.scale) if backend == "numba" else None)
    if pose is None:
        pose = _newton_checked(platform, L, prev, tol, max_iter)
    if verify is None:
        verify = platform.layout is not None
    if verify:
        _verify_nearest(platform, L, prev, pose, tol, backend)
    return pose


def _newton_checked(platform: Platform, L: np.ndarray, prev: np.ndarray, tol: float,
                    max_iter: int) -> np.ndarray:
    """:func:`_newton` from ``prev``, its convergence and determinant signs checked."""
    pose, res, signs = _newton(platform, L, prev, tol, max_iter)
    if np.any(~(res <= tol)):
        raise UnreachableError(
            f"tracking forward kinematics did not converge from the previous pose (leg error "
            f"{float(np.nanmax(res)):.3g} {platform.length_unit}): the legs moved too far or "
            "admit no assembly; re-initialise with fk_list")
    flipped = np.any(signs != signs[..., :1], axis=-1) | np.any(signs == 0, axis=-1)
    if np.any(flipped):
        raise SingularityError(
            "tracking crossed a singular configuration (the line Jacobian's determinant changed "
            "sign between the previous pose and the solution): the assembly mode is ambiguous; "
            "re-initialise with fk_list")
    return pose


def _verify_nearest(platform: Platform, L: np.ndarray, prev: np.ndarray, pose: np.ndarray,
                    tol: float, backend: Backend = "numpy") -> None:
    """Raise :class:`SingularityError` unless ``pose`` is the assembly mode nearest ``prev``
    (``backend="numba"``: the distances compiled, :func:`_fk_kernels.nearest_moved_kernel`)."""
    sol = fk_all(platform, L, tol=max(tol, 1e-9))
    if backend == "numba":
        n = sol.valid.shape[-1]
        moved = np.empty(math.prod(L.shape[:-1]), dtype=bool)
        _fk_kernels.nearest_moved_kernel(
            np.ascontiguousarray(sol.poses).reshape(-1, n, 4, 4), sol.valid.reshape(-1, n),
            np.ascontiguousarray(prev).reshape(-1, 4, 4),
            np.ascontiguousarray(pose, dtype=float).reshape(-1, 4, 4), float(platform.scale),
            moved)
    else:
        d = _pose_distance(sol.poses, prev[..., None, :, :], platform.scale)
        d = np.where(sol.valid, d, np.inf)
        nearest = np.take_along_axis(sol.poses, np.argmin(d, axis=-1)[..., None, None, None],
                                     axis=-3)[..., 0, :, :]
        moved = _pose_distance(nearest, pose, platform.scale) > 1e-6
    if np.any(moved):
        raise SingularityError(
            "tracking converged to an assembly mode that is not the one nearest the "
            "previous pose: the motion between samples was too large; re-initialise with "
            "fk_list")

