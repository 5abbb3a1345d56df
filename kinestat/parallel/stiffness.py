"""Spatial stiffness of the loaded compliant platform (Vibhute 2011 eq. 2-17, after Griffis).

The stiffness maps a small displacement of the top to the change of the external wrench
``w = j f`` (see :mod:`kinestat.parallel.statics`) that holds it there: ``δw = K δD``
(Vibhute eq. 2-16). By default ``δD = [δx_O; δφ]`` (ray order, Griffis & Duffy: translation of
the point of the top at the base origin, then the small rotation, base frame), which makes
``K`` symmetric when the platform is unloaded. ``twist_order="axis"`` takes the project's twist
order ``[δφ; δx_O]`` instead: ``K_axis = K_ray Δ`` with Δ swapping the two halves.

Derivation (ours). With ``X_i = B_i + l_i S_i`` the top point of leg i,
``δX_i = δx_O + δφ × X_i``, so ``δl_i = S_i·δX_i = $_iᵀ δD`` (``$_i = [S_i; B_i × S_i]``) and
``δS_i = (I − S_i S_iᵀ) δX_i / l_i``. Differentiating ``w = Σ f_i $_i`` with
``δf_i = k_i δl_i``::

    K = j k jᵀ                                             (elastic term)
      + Σ_i (f_i / l_i) Σ_{e ⊥ S_i} [e; B_i × e][e; B_i × e]ᵀ    (two symmetric geometric terms)
      − Σ_i f_i [I; [B_i]×] [0, [S_i]×]                      (non-symmetric load terms)

For spring legs ``f_i / l_i = k_i (1 − ρ_i)`` with ``ρ_i = l0_i / l_i`` (eq. 2-18) and
``[e; B_i × e]`` for the two unit vectors ``e`` normal to the leg are the derivatives of the
leg's Plücker coordinates with respect to the two angles that fix its direction (base point
held): the first three terms are exactly those of eq. 2-17,
``[j][k][j]ᵀ + [δj/δφ][k(1−ρ)][δj/δφ]ᵀ + [δj/δψ][k(1−ρ)][δj/δψ]ᵀ``; the last term plays the part of
eq. 2-17's two non-symmetric ``V`` terms (eqs. 2-19 to 2-23, not legible enough in our copy to
check term by term). Its antisymmetric part is fixed by the load alone: with ``w = [F; M]``::

    K − Kᵀ = −[[0, [F]×], [[F]×, [M]×]]

so K is symmetric exactly when the platform is unloaded. Finite differences of
:func:`~kinestat.parallel.statics.spring_wrench` confirm K (tests/parallel/test_stiffness.py).
"""

from __future__ import annotations

import weakref

import numpy as np

from kinestat.errors import InputError, UnreachableError
from kinestat.parallel import _stiffness_kernels as _sk
from kinestat.parallel._refine import apply_twist
from kinestat.parallel.legs import as_pose, leg_directions_trusted
from kinestat.parallel.platform import Platform
from kinestat.parallel.statics import spring_wrench
from kinestat.spatial.transforms import as_array, skew
from kinestat.spatial.validate import as_rotation

__all__ = ["stiffness", "stiffness_axis_trusted", "stiffness_terms", "load_asymmetry",
           "equilibrium_pose",
           "tip_compliance", "tip_compliance_one", "pinned_tip_step", "platform_arrays",
           "tip_stiffness", "TWIST_ORDERS"]

TWIST_ORDERS = ("ray", "axis")


def _swap(K: np.ndarray) -> np.ndarray:
    return np.concatenate([K[..., 3:], K[..., :3]], axis=-1)


def stiffness_terms(platform: Platform, pose, forces=None) -> dict[str, np.ndarray]:
    """The three parts of K (ray order): ``elastic``, ``geometric`` (symmetric), ``load``.

    ``forces`` (..., 6) are the leg tensions; default the springs' ``k (l − l0)`` at ``pose``.
    """
    return _terms(platform, as_pose(pose), forces)


def _terms(platform: Platform, T: np.ndarray, forces=None) -> dict[str, np.ndarray]:
    """:func:`stiffness_terms` at checked poses ``T``."""
    S, l = leg_directions_trusted(platform, T)
    f = platform.stiffness * (l - platform.free_lengths) if forces is None else as_array(
        forces, shape_tail=(6,), name="leg forces")
    B = platform.base_points
    lines = np.concatenate([S, np.cross(B, S)], axis=-1)  # (..., 6, 6) rows $_i
    elastic = np.einsum("...ia,...i,...ib->...ab", lines, platform.stiffness, lines)
    # I − S Sᵀ as a sum over the normals: [I; [B]x] (I − SSᵀ) [I; [B]x]ᵀ
    P = np.eye(3) - S[..., :, None] * S[..., None, :]  # (..., 6, 3, 3)
    Bx = skew(B)  # (6, 3, 3)
    top = P
    bot = Bx @ P
    G = np.concatenate([np.concatenate([top, top @ np.swapaxes(Bx, -1, -2)], -1),
                        np.concatenate([bot, bot @ np.swapaxes(Bx, -1, -2)], -1)], -2)
    geometric = np.einsum("...i,...iab->...ab", f / l, G)
    Sx = skew(S)
    load_i = np.zeros(S.shape[:-1] + (6, 6))
    load_i[..., :3, 3:] = -Sx
    load_i[..., 3:, 3:] = -(Bx @ Sx)
    load = np.einsum("...i,...iab->...ab", f, load_i)
    return {"elastic": elastic, "geometric": geometric, "load": load}


def stiffness(platform: Platform, pose, forces=None, *, twist_order: str = "ray") -> np.ndarray:
    """Spatial stiffness K (..., 6, 6) of the platform at ``pose`` under leg tensions ``forces``.

    ``δw = K δD``, w the external wrench ``[f; m_O0]`` (base frame) and δD the small twist of
    the top in ``twist_order`` ("ray": ``[δx_O; δφ]``, default; "axis": ``[δφ; δx_O]``).
    ``forces`` default to the spring tensions ``k (l − l0)`` at the pose; pass ``j⁻¹ w``
    (:func:`~kinestat.parallel.statics.forces_from_wrench`) for the stiffness under a given
    load ``w``.
    """
    if twist_order not in TWIST_ORDERS:
        raise InputError(f"twist_order must be one of {TWIST_ORDERS}, got {twist_order!r}")
    parts = stiffness_terms(platform, pose, forces)
    K = parts["elastic"] + parts["geometric"] + parts["load"]
    return K if twist_order == "ray" else _swap(K)


def stiffness_axis_trusted(platform: Platform, T: np.ndarray) -> np.ndarray:
    """``stiffness(platform, T, twist_order="axis")`` (the springs' own tensions) at one pose
    ``T`` (4, 4) the caller has checked, compiled
    (:func:`kinestat.parallel._stiffness_kernels.stiffness_axis_one`, the hot path of a control
    cycle): no validation; equal to :func:`stiffness` to rounding (~1e-15 relative)."""
    K = np.empty((6, 6))
    if _sk.stiffness_axis_one(*_platform_arrays(platform), np.array(T, dtype=float), K):
        return K
    parts = _terms(platform, np.asarray(T, dtype=float))  # raises: a leg of zero length
    return _swap(parts["elastic"] + parts["geometric"] + parts["load"])  # pragma: no cover


def tip_compliance_one(K: np.ndarray, tip) -> np.ndarray:
    """:func:`tip_compliance` (3, 3) of ONE tip ``tip`` (3,) given the stiffness ``K`` (6, 6,
    axis order) at the pose, compiled (:func:`~kinestat.parallel._stiffness_kernels.
    tip_compliance_one`): no validation; equal to :func:`tip_compliance` to rounding.

    Raises:
        numpy.linalg.LinAlgError: ``K`` is singular (as :func:`tip_compliance`).
    """
    C = np.empty((3, 3))
    p = np.array(tip, dtype=float)
    if not _sk.tip_compliance_one(np.ascontiguousarray(K, dtype=float), p, C):
        return tip_compliance(None, None, p, stiffness_axis=K)  # raises LinAlgError
    return C


def pinned_tip_step(platform: Platform, T: np.ndarray, K: np.ndarray, tip, u,
                    force) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """The platform's first-order response at the pose ``T`` (4, 4; stiffness ``K`` (6, 6),
    axis order) when the base moves so that the tip ``tip`` (3,), pinned in space, sits at
    ``tip + u`` in the base frame, ``force`` (3,) the external force on the tip (base frame):
    ``(δF, D, δl, T')`` — the change of the tip force (3,), the top's twist ``[δφ; δx_O]``
    (6,), the legs' length changes ``jᵀ D`` (6,) and the moved top pose (4, 4), from
    ``K D = [δF; p × δF + u × F]`` and ``[−[p]×, I] D = u`` (Vibhute eq. 2-16/2-17 to first
    order), compiled (:func:`~kinestat.parallel._stiffness_kernels.pinned_tip_step_one`); None
    when ``K`` or the tip compliance is singular or a leg has zero length (the caller falls
    back to its NumPy formulation, which raises)."""
    B, P_top, _, _ = _platform_arrays(platform)
    dF, D, dl, top = np.empty(3), np.empty(6), np.empty(6), np.empty((4, 4))
    ok = _sk.pinned_tip_step_one(B, P_top, np.ascontiguousarray(T, dtype=float),
                                 np.ascontiguousarray(K, dtype=float),
                                 np.array(tip, dtype=float), np.array(u, dtype=float),
                                 np.array(force, dtype=float), dF, D, dl, top)
    return (dF, D, dl, top) if ok else None


_ARRAYS: dict[int, tuple] = {}


def platform_arrays(platform: Platform) -> tuple:
    """``(base_points, top_points, stiffness, free_lengths)`` of ``platform`` as writeable C
    arrays, made once per platform, for compiled single-pose kernels (do not modify them)."""
    return _platform_arrays(platform)


def _platform_arrays(platform: Platform) -> tuple:
    """The platform's base points, top points, springs and free lengths as writeable C arrays
    (the kernel compiles for one array type), made once per platform."""
    a = _ARRAYS.get(id(platform))
    if a is None:
        a = _ARRAYS[id(platform)] = tuple(
            np.array(v, dtype=float) for v in (platform.base_points, platform.top_points,
                                               platform.stiffness, platform.free_lengths))
        weakref.finalize(platform, _ARRAYS.pop, id(platform), None)
    return a


def tip_compliance(platform: Platform, pose, tip, *, stiffness_axis=None) -> np.ndarray:
    """Translational compliance (..., 3, 3) of a point ``tip`` of the top, base frame, mm/N.

    A force ``δF`` applied at the tip (the top free to rotate) moves the tip by ``C_tip δF``:
    ``C_tip = [−[p]×, I] K⁻¹ [I; [p]×]``, K the platform's stiffness at ``pose`` (Vibhute
    eq. 2-16/2-17, axis order ``[δφ; δx_O]``) and ``p`` (..., 3) the tip in base coordinates.
    Batched over a leading shape shared by ``pose`` and ``tip``. ``stiffness_axis``: K at
    ``pose`` in axis order when the caller already has it (not recomputed).

    >>> from kinestat.parallel.platform import special_6_6
    >>> pf = special_6_6()
    >>> C = tip_compliance(pf, pf.home_pose, [0.0, 0.0, 100.0])
    >>> bool(np.allclose(C, C.T)) and bool(np.all(np.linalg.eigvalsh(C) > 0))
    True
    """
    K = (stiffness(platform, pose, twist_order="axis") if stiffness_axis is None
         else stiffness_axis)
    p = as_array(tip, shape_tail=(3,), name="tip")
    P = skew(p)
    eye = np.broadcast_to(np.eye(3), P.shape)
    A = np.concatenate([eye, P], axis=-2)
    B = np.concatenate([-P, eye], axis=-1)
    return B @ np.linalg.solve(K, A)


def tip_stiffness(platform: Platform, pose, tip, rotation=None, *,
                  stiffness_axis=None) -> np.ndarray:
    """Point stiffness (..., 3, 3) of the platform at ``tip``, N/mm: ``C_tip⁻¹``
    (:func:`tip_compliance`), in the base frame, or rotated by ``rotation`` (..., 3, 3, the
    base frame's orientation in another frame) into that frame: ``R C_tip⁻¹ Rᵀ``.

    Moving the base by ``δ`` at the tip with the tip held changes the tip force by
    ``K_tip δ`` (Vibhute eq. 2-16 reduced to the tip's translation).
    """
    Kb = np.linalg.inv(tip_compliance(platform, pose, tip, stiffness_axis=stiffness_axis))
    if rotation is None:
        return Kb
    R = as_rotation(rotation, "rotation")
    return R @ Kb @ np.swapaxes(R, -1, -2)


def load_asymmetry(wrench) -> np.ndarray:
    """``K − Kᵀ`` due to the load ``w = [F; M]``: ``−[[0, [F]×], [[F]×, [M]×]]`` (ray order)."""
    w = as_array(wrench, shape_tail=(6,), name="wrench")
    Fx, Mx = skew(w[..., :3]), skew(w[..., 3:])
    out = np.zeros(w.shape[:-1] + (6, 6))
    out[..., :3, 3:] = -Fx
    out[..., 3:, :3] = -Fx
    out[..., 3:, 3:] = -Mx
    return out


def equilibrium_pose(platform: Platform, wrench, guess=None, *, tol: float = 1e-9,
                     max_iter: int = 50) -> np.ndarray:
    """The pose at which the springs balance the external wrench ``w`` (Newton on K), batched.

    Solves ``spring_wrench(platform, pose) = w`` from ``guess`` (default home). ``tol`` is on
    the wrench error, relative to ``max(1, |w|)`` in the model's force unit.

    Raises:
        UnreachableError: no convergence (load beyond what the springs hold near the guess, or
            a singular configuration on the way).
    """
    w = as_array(wrench, shape_tail=(6,), name="wrench")
    g = platform.home_pose if guess is None else as_pose(guess, "guess")
    pose = np.broadcast_to(g, w.shape[:-1] + (4, 4)).copy()
    s = platform.scale
    wscale = np.maximum(1.0, np.linalg.norm(w, axis=-1))
    err = np.inf
    for _ in range(max_iter):
        r = w - spring_wrench(platform, pose)
        err = np.linalg.norm(r, axis=-1) / wscale
        if np.all(err <= tol):
            break
        K = stiffness(platform, pose)
        dD = np.linalg.solve(K, r[..., None])[..., 0]  # [δx; δφ]
        f = np.maximum(1.0, np.maximum(np.linalg.norm(dD[..., 3:], axis=-1) / 0.2,
                                       np.linalg.norm(dD[..., :3], axis=-1) / (0.2 * s)))
        dD = dD / f[..., None]
        pose = apply_twist(pose, np.concatenate([dD[..., 3:], dD[..., :3]], axis=-1))
    if not np.all(err <= tol):
        raise UnreachableError(
            f"no equilibrium found for wrench {np.round(w, 6).tolist()} (relative wrench error "
            f"{float(np.max(err)):.3g} after {max_iter} Newton steps): the load may exceed what "
            "the springs hold near the guess")
    return pose
