"""Kinestatic decomposition of a twist into a twist of freedom and a twist of compliance, batched.

Griffis & Duffy 1991 (Kinestatic control, Trans. ASME J. Mech. Des. 113(4)); Vibhute 2011
§2.1.3.3. A compliant coupling of stiffness ``K`` carries a tool that touches a rigid
environment; the contact can exert the wrenches spanned by the columns of ``W`` (6×m). A small
twist ``T`` of the coupling splits uniquely into

* a **twist of freedom** ``T_f``, reciprocal to every contact wrench (``Wᵀ Δ T_f = 0``): the
  motion the contact allows, which does no work against it, and
* a **twist of compliance** ``T_c = K⁻¹ W λ``: the deflection of the coupling that changes the
  wrench by ``δw = K T_c = W λ``, a wrench the contact can supply.

Eliminating ``T_f`` from ``T = T_f + K⁻¹ W λ`` with ``Wᵀ Δ T_f = 0`` gives
(:func:`decompose_twist`)::

    λ = (Wᵀ Δ K⁻¹ W)⁻¹ Wᵀ Δ T,    T_c = K⁻¹ W λ,    T_f = T − T_c

and the inverse problem (:func:`compose_twist`): to change the wrench by ``δw = W λ`` while
moving by the twist of freedom ``T_f``, move by ``T = T_f + K⁻¹ δw``.

Conventions (every function here):

* twists ``T`` in **axis** coordinates ``[ω; v_O]`` (rotation, then the velocity of the point at
  the origin O), the project's twist order (:mod:`kinestat.spatial.screws`);
* wrenches in **ray** coordinates ``[f; m_O]`` (force, then moment about O), the same frame;
* ``Δ = [[0, I], [I, 0]]``, the reciprocal product ``w∘T = wᵀ Δ T = f·v_O + m_O·ω`` (the power);
* ``K`` (6×6) maps an axis-order twist to a wrench, ``δw = K T``. The platform's
  :func:`~kinestat.parallel.stiffness.stiffness` defaults to the ray twist order
  ``δD = [δx_O; δφ] = Δ T``; :func:`axis_stiffness` converts, ``K_axis = K_ray Δ``.

Which twist, which sign. K is the platform's: ``T`` the twist of the top relative to the base,
``δw`` the change of the external wrench on the top. Decomposing that relative twist, the wrench
on the top changes by ``+W λ``. In kinestatic control the decomposed twist is usually the
robot's motion ``T_robot`` of the base while the tool (top) touches a rigid environment: the top
then moves by ``T_f`` and deflects by ``T_f − T_robot = −T_c``, so the external wrench on the top
changes by ``−W λ`` (the planar example, :mod:`kinestat.parallel.planar_wheel`, has ``λ = −δN``).

The elliptic metric (Griffis & Duffy). ``K T_c = W λ`` and ``Wᵀ Δ T_f = 0`` give
``T_fᵀ Δ K T_c = λᵀ Wᵀ Δ T_f = 0``: the wrench that the twist of compliance produces does no
work on the twist of freedom. ``Δ K_axis = Δ K_ray Δ`` is symmetric, and then
``⟨T1, T2⟩ = T1ᵀ Δ K T2`` is the positive definite "elliptic" inner product of §2.1.3.3, only
when the ray-order stiffness is symmetric positive definite, i.e. **unloaded**. Under load ``K``
is not symmetric (:func:`~kinestat.parallel.stiffness.load_asymmetry`), the product is not, and
the orthogonality is one-sided: ``T_fᵀ Δ K T_c = 0`` holds, ``T_cᵀ Δ K T_f`` in general does not
(tests/parallel/test_kinestatic.py checks both).

Shapes: ``K`` (..., 6, 6), ``W`` (..., 6, m) with 1 ≤ m ≤ 6 (a single wrench may be given as
(6,)), ``T`` (..., 6); leading batch dimensions broadcast. Degenerate inputs raise
:class:`~kinestat.errors.InputError` (bad shapes, m outside 1..6, linearly dependent contact
wrenches, a twist of freedom that is not reciprocal, a wrench change outside span W) or
:class:`~kinestat.errors.SingularityError` (K singular, ``Wᵀ Δ K⁻¹ W`` singular).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from kinestat.errors import InputError, SingularityError
from kinestat.parallel import _kinestatic_kernels as _kk
from kinestat.parallel.statics import forces_from_wrench
from kinestat.parallel.stiffness import stiffness
from kinestat.spatial.transforms import as_array

__all__ = [
    "DELTA",
    "TwistSplit",
    "axis_stiffness",
    "contact_basis",
    "reciprocal_products",
    "elliptic_product",
    "compliance_twists",
    "decompose_twist",
    "compose_twist",
    "compose_twist_line",
    "solve_one",
    "wrench_coordinates",
    "freedom_basis",
    "platform_stiffness_axis",
]

#: Δ = [[0, I], [I, 0]]: ``wᵀ Δ T`` is the reciprocal product of a wrench and a twist.
DELTA = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])
DELTA.setflags(write=False)

_K_TOL = 1e-12  # K is singular when s_min / s_max ≤ this
_W_TOL = 1e-9  # contact wrenches dependent when s_min / s_max of the unit columns ≤ this
_G_TOL = 1e-10  # Wᵀ Δ K⁻¹ W singular when s_min ≤ this × |K⁻¹| (unit columns of W)
_IN_TOL = 1e-9  # relative tolerance of the input checks of compose_twist
_TINY = float(np.finfo(float).tiny)


class TwistSplit(NamedTuple):
    """The kinestatic decomposition ``T = freedom + compliance``, ``compliance = K⁻¹ W lam``."""

    freedom: np.ndarray  #: (..., 6) the twist of freedom T_f, axis order [ω; v_O]
    compliance: np.ndarray  #: (..., 6) the twist of compliance T_c, axis order [ω; v_O]
    lam: np.ndarray  #: (..., m) λ: the wrench change is W λ


def _where(mask: np.ndarray) -> str:
    if mask.ndim == 0:
        return ""
    return f" at batch index {tuple(int(i) for i in np.argwhere(mask)[0])}"


def axis_stiffness(K, twist_order: str = "ray") -> np.ndarray:
    """K (..., 6, 6) acting on axis-order twists ``[ω; v_O]``, from K in ``twist_order``.

    ``twist_order="ray"`` (the platform stiffness's default, ``δD = [δx_O; δφ]``):
    ``K_axis = K_ray Δ`` (its column halves swapped). ``"axis"``: returned as a copy.

    >>> K_ray = np.diag([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    >>> axis_stiffness(K_ray)[0]  # f_x = 1·δx_O, and δx_O is T[3]
    array([0., 0., 0., 1., 0., 0.])
    """
    K = as_array(K, shape_tail=(6, 6), name="stiffness K")
    if twist_order == "axis":
        return K.copy()
    if twist_order == "ray":
        return K @ DELTA
    raise InputError(f"twist_order must be 'ray' or 'axis', got {twist_order!r}")


def contact_basis(W) -> np.ndarray:
    """The contact wrenches as a (..., 6, m) array, checked: 1 ≤ m ≤ 6, linearly independent.
    Six independent wrenches constrain every twist: the twist of freedom is zero and the whole
    twist is compliance (a tool held fast).

    A single wrench may be given as (6,). Columns are ray-order wrenches ``[f; m_O]``.
    """
    W = as_array(W, name="contact wrenches W")
    if W.ndim == 1:
        W = W[:, None]
    if W.ndim < 2 or W.shape[-2] != 6:
        raise InputError(f"contact wrenches W must have shape (..., 6, m) (columns [f; m_O]), "
                         f"got {W.shape}")
    m = W.shape[-1]
    if not 1 <= m <= 6:
        raise InputError(f"the contact must exert 1 to 6 independent wrenches, got m = {m} "
                         "(m = 0 leaves nothing to decompose; more than 6 cannot be "
                         "independent)")
    norms = np.linalg.norm(W, axis=-2)
    zero = norms == 0.0
    if np.any(zero):
        raise InputError(f"contact wrench {int(np.argwhere(zero)[0][-1]) + 1} is zero"
                         f"{_where(np.any(zero, axis=-1))}")
    s = np.linalg.svd(W / norms[..., None, :], compute_uv=False)
    dep = s[..., -1] <= _W_TOL * s[..., 0]
    if np.any(dep):
        sv = s[tuple(np.argwhere(dep)[0])] if dep.ndim else s
        rank = int(np.sum(sv > _W_TOL * sv[0]))
        raise InputError(f"the {m} contact wrenches are linearly dependent{_where(dep)} "
                         f"(rank {rank} < {m}); give a basis of the wrenches the contact can "
                         "exert")
    return W


def _twist(T, name: str = "twist T") -> np.ndarray:
    return as_array(T, shape_tail=(6,), name=name)


def reciprocal_products(W, T) -> np.ndarray:
    """``Wᵀ Δ T`` (..., m): the power of each contact wrench on the twist (Duffy's ``w∘T``)."""
    W = contact_basis(W)
    T = _twist(T)
    return np.einsum("...im,...i->...m", W, T @ DELTA)


def elliptic_product(K, T1, T2) -> np.ndarray:
    """``T1ᵀ Δ K T2`` (...,): the power of the wrench ``K T2`` on ``T1`` (Griffis & Duffy).

    Symmetric in T1, T2 (the elliptic metric) only when K is unloaded; see the module notes.
    """
    K = as_array(K, shape_tail=(6, 6), name="stiffness K")
    w2 = np.einsum("...ij,...j->...i", K, _twist(T2, "twist T2"))
    return np.einsum("...i,...i->...", _twist(T1, "twist T1") @ DELTA, w2)


def _check_stiffness(K) -> tuple[np.ndarray, np.ndarray]:
    """K as an array and its smallest singular value; SingularityError when K is singular."""
    K = as_array(K, shape_tail=(6, 6), name="stiffness K")
    s = np.linalg.svd(K, compute_uv=False)
    bad = s[..., -1] <= _K_TOL * s[..., 0]
    if np.any(bad):
        raise SingularityError(f"the stiffness K is singular{_where(bad)} (s_min/s_max = "
                               f"{float(np.min(s[..., -1] / s[..., 0])):.3g}): some twist "
                               "costs no wrench, so the twist of compliance is not determined")
    return K, s[..., -1]


def _solve(K: np.ndarray, W: np.ndarray) -> np.ndarray:
    batch = np.broadcast_shapes(K.shape[:-2], W.shape[:-2])
    return np.linalg.solve(np.broadcast_to(K, batch + (6, 6)),
                           np.broadcast_to(W, batch + W.shape[-2:]))


def compliance_twists(K, W) -> np.ndarray:
    """``K⁻¹ W`` (..., 6, m): the twists of compliance of the contact wrenches (axis order)."""
    K, _ = _check_stiffness(K)
    return _solve(K, contact_basis(W))


def _gram(W: np.ndarray, X: np.ndarray, k_min: np.ndarray) -> np.ndarray:
    """``G = Wᵀ Δ K⁻¹ W`` with ``X = K⁻¹ W``, checked for singularity."""
    G = np.einsum("...im,...in->...mn", DELTA @ W, X)
    n = np.linalg.norm(W, axis=-2)
    Gn = G / (n[..., :, None] * n[..., None, :])
    cinv = 1.0 / k_min  # |K⁻¹|₂
    s = np.linalg.svd(Gn, compute_uv=False)
    bad = s[..., -1] <= _G_TOL * cinv
    if np.any(bad):
        raise SingularityError(
            f"Wᵀ Δ K⁻¹ W is singular{_where(bad)}: a combination of the contact wrenches does "
            "no work on its own twist of compliance, so the decomposition is not unique (a "
            "loaded, non-positive-definite stiffness, or a contact the coupling cannot load)")
    return G


def decompose_twist(K, W, T) -> TwistSplit:
    """Split ``T = T_f + T_c`` (Griffis & Duffy 1991; Vibhute §2.1.3.3), batched.

    ``λ = (Wᵀ Δ K⁻¹ W)⁻¹ Wᵀ Δ T``, ``T_c = K⁻¹ W λ``, ``T_f = T − T_c``: ``T_f`` is reciprocal to
    every column of ``W`` and the wrench changes by ``K T_c = W λ``. ``K`` axis order (see
    :func:`axis_stiffness`), ``W`` (..., 6, m) ray-order wrenches, ``T`` (..., 6) axis order.
    One step of iterative refinement keeps ``Wᵀ Δ T_f`` at rounding level.

    >>> K = np.diag([10.0, 10.0, 10.0, 1.0, 1.0, 1.0]) @ DELTA  # ray: 10·δx, 1·δφ
    >>> s = decompose_twist(K, [0, 0, 1, 0, 0, 0], [0, 0, 0, 1.0, 0, 2.0])  # push along z
    >>> s.freedom, s.compliance, s.lam
    (array([0., 0., 0., 1., 0., 0.]), array([0., 0., 0., 0., 0., 2.]), array([20.]))
    """
    K, k_min = _check_stiffness(K)
    W = contact_basis(W)
    T = _twist(T)
    X = _solve(K, W)
    G = _gram(W, X, k_min)
    b = np.einsum("...im,...i->...m", W, T @ DELTA)
    lam = np.linalg.solve(G, b[..., None])[..., 0]
    Tc = np.einsum("...im,...m->...i", X, lam)
    Tf = T - Tc
    # one refinement step: remove the rounding left in Wᵀ Δ T_f
    r = np.einsum("...im,...i->...m", W, Tf @ DELTA)
    dl = np.linalg.solve(G, r[..., None])[..., 0]
    lam = lam + dl
    Tc = Tc + np.einsum("...im,...m->...i", X, dl)
    return TwistSplit(T - Tc, Tc, lam)


def wrench_coordinates(W, delta_wrench) -> np.ndarray:
    """λ (..., m) with ``W λ = δw``; InputError when ``δw`` is not in span W (relative 1e-9)."""
    W = contact_basis(W)
    dw = as_array(delta_wrench, shape_tail=(6,), name="wrench change")
    lam = np.einsum("...mi,...i->...m", np.linalg.pinv(W), dw)
    res = dw - np.einsum("...im,...m->...i", W, lam)
    scale = np.maximum(np.linalg.norm(dw, axis=-1), np.finfo(float).tiny)
    bad = np.linalg.norm(res, axis=-1) > _IN_TOL * scale
    if np.any(bad):
        raise InputError(f"the wrench change is not one the contact can exert{_where(bad)}: "
                         "it is not a combination of the contact wrenches W")
    return lam


def compose_twist(K, W, freedom, delta_wrench) -> np.ndarray:
    """The twist ``T = T_f + K⁻¹ δw`` that moves by ``T_f`` and changes the wrench by ``δw``.

    The inverse of :func:`decompose_twist` (Griffis & Duffy 1991): ``freedom`` (..., 6) must be
    reciprocal to ``W`` and ``delta_wrench`` (..., 6) in span W, both to a relative 1e-9, else
    InputError. Returns the axis-order twist (..., 6).

    >>> K = np.diag([10.0, 10.0, 10.0, 1.0, 1.0, 1.0]) @ DELTA
    >>> compose_twist(K, [0, 0, 1, 0, 0, 0], [0, 0, 0, 1.0, 0, 0], [0, 0, 20.0, 0, 0, 0])
    array([0., 0., 0., 1., 0., 2.])
    """
    K, _ = _check_stiffness(K)
    W = contact_basis(W)
    Tf = _twist(freedom, "twist of freedom")
    wrench_coordinates(W, delta_wrench)
    dw = as_array(delta_wrench, shape_tail=(6,), name="wrench change")
    r = np.einsum("...im,...i->...m", W, Tf @ DELTA)
    scale = np.linalg.norm(W, axis=-2) * np.linalg.norm(Tf, axis=-1)[..., None]
    bad = np.any(np.abs(r) > _IN_TOL * np.maximum(scale, np.finfo(float).tiny), axis=-1)
    if np.any(bad):
        worst = float(np.max(np.abs(r) / np.maximum(scale, np.finfo(float).tiny)))
        raise InputError(f"the twist of freedom is not reciprocal to the contact wrenches"
                         f"{_where(bad)} (relative |Wᵀ Δ T_f| = {worst:.3g}): it would push "
                         "into the contact; project it with decompose_twist first")
    return Tf + np.linalg.solve(K, dw[..., None])[..., 0]


def compose_twist_line(K, w, freedom, delta_wrench) -> np.ndarray:
    """:func:`compose_twist` for ONE pose and ONE contact wrench ``w`` (6,) (a point contact):
    the same checks in the same order with the same messages (singular K, zero wrench, a
    wrench change not along ``w``, a twist of freedom not reciprocal to ``w``) and the same
    value ``T_f + K⁻¹ δw``, without the batched machinery (the control cycle's hot path).
    The span check projects on ``w`` directly instead of through a pseudo-inverse, and the
    vector checks run in scalar arithmetic; they agree with the batched ones to rounding, far
    inside the 1e-9 tolerance. K's singularity check takes LAPACK's SVD only where the compiled
    one-sided Jacobi ratio ``s_min/s_max`` (:func:`~kinestat.parallel._kinestatic_kernels.
    singular_ratio6`, accurate to ~1e-15 of ``s_max``) is not clearly above the threshold
    (twice it): the same verdicts, without the SVD on a regular K.

    >>> K = np.diag([10.0, 10.0, 10.0, 1.0, 1.0, 1.0]) @ DELTA
    >>> compose_twist_line(K, np.array([0, 0, 1.0, 0, 0, 0]), np.array([0, 0, 0, 1.0, 0, 0]),
    ...                    np.array([0, 0, 20.0, 0, 0, 0]))
    array([0., 0., 0., 1., 0., 2.])
    """
    K = np.asarray(K, dtype=float)
    w = np.asarray(w, dtype=float)
    Tf = np.asarray(freedom, dtype=float)
    dw = np.asarray(delta_wrench, dtype=float)
    # a regular K (the Jacobi ratio clearly above the threshold; 0 for a non-finite K) skips
    # the checks below, which raise their messages: a bad shape, not finite, singular
    if not (K.shape == (6, 6) and _kk.singular_ratio6(np.ascontiguousarray(K)) > 2.0 * _K_TOL):
        ok = K.shape == (6, 6) and all(map(math.isfinite, K.ravel().tolist()))
        s = np.linalg.svd(K, compute_uv=False) if ok else None
        if s is None or s[-1] <= _K_TOL * s[0]:
            K, _ = _check_stiffness(K)
    vals = []
    for v, name in ((w, "contact wrenches W"), (Tf, "twist of freedom"), (dw, "wrench change")):
        x = v.tolist()
        if v.shape != (6,) or not all(map(math.isfinite, x)):
            raise InputError(f"{name} must be 6 finite numbers, got {x}")
        vals.append(x)
    (w0, w1, w2, w3, w4, w5), (t0, t1, t2, t3, t4, t5), (d0, d1, d2, d3, d4, d5) = vals
    # the sums of the batched checks, term by term in the same order
    wn = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2 + w3 * w3 + w4 * w4 + w5 * w5)
    if wn == 0.0:
        raise InputError("contact wrench 1 is zero")
    c = (w0 * d0 + w1 * d1 + w2 * d2 + w3 * d3 + w4 * d4 + w5 * d5) / (wn * wn)
    res = math.sqrt((d0 - w0 * c) ** 2 + (d1 - w1 * c) ** 2 + (d2 - w2 * c) ** 2
                    + (d3 - w3 * c) ** 2 + (d4 - w4 * c) ** 2 + (d5 - w5 * c) ** 2)
    dn = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2 + d3 * d3 + d4 * d4 + d5 * d5)
    if res > _IN_TOL * max(dn, _TINY):
        raise InputError("the wrench change is not one the contact can exert: it is not a "
                         "combination of the contact wrenches W")
    r = w0 * t3 + w1 * t4 + w2 * t5 + w3 * t0 + w4 * t1 + w5 * t2  # w · (T_f Δ)
    scale = max(wn * math.sqrt(t0 * t0 + t1 * t1 + t2 * t2 + t3 * t3 + t4 * t4 + t5 * t5),
                _TINY)
    if abs(r) > _IN_TOL * scale:
        raise InputError(f"the twist of freedom is not reciprocal to the contact wrenches "
                         f"(relative |Wᵀ Δ T_f| = {abs(r) / scale:.3g}): it would push "
                         "into the contact; project it with decompose_twist first")
    return Tf + np.linalg.solve(K, dw[..., None])[..., 0]


def solve_one(K, b) -> np.ndarray:
    """``K⁻¹ b`` (6,) for ONE stiffness ``K`` (6, 6) and ONE wrench ``b`` (6,), compiled
    (:func:`~kinestat.parallel._kinestatic_kernels.solve6`, Gaussian elimination with partial
    pivoting): ``numpy.linalg.solve``'s value to rounding, without its set-up (the control
    cycle's twists of compliance). No validation; a singular K runs ``numpy.linalg.solve``,
    which raises :class:`numpy.linalg.LinAlgError`.

    >>> solve_one(np.diag([1.0, 2.0, 4.0, 1.0, 1.0, 1.0]), np.ones(6)).tolist()
    [1.0, 0.5, 0.25, 1.0, 1.0, 1.0]
    """
    K = np.ascontiguousarray(K, dtype=float)
    b = np.array(b, dtype=float)
    x = np.empty(6)
    if K.shape == (6, 6) and b.shape == (6,) and _kk.solve6(K, b, x):
        return x
    return np.linalg.solve(K, b)


def freedom_basis(W) -> np.ndarray:
    """An orthonormal basis (..., 6, 6 − m) of the twists reciprocal to W (``Wᵀ Δ N = 0``).

    The columns span the twists of freedom (axis order); from the SVD of ``Wᵀ Δ``.
    """
    W = contact_basis(W)
    m = W.shape[-1]
    A = np.swapaxes(W, -1, -2) @ DELTA  # (..., m, 6)
    _, _, vt = np.linalg.svd(A)
    return np.swapaxes(vt[..., m:, :], -1, -2)


def platform_stiffness_axis(platform, pose, wrench=None) -> np.ndarray:
    """Axis-order K of a platform at ``pose``, loaded by its springs or by ``wrench``.

    The same K as ``kinestat platform stiffness --pose P [--wrench W0] --twist-order axis``:
    with ``wrench`` the legs carry ``j⁻¹ w`` (Vibhute eq. 2-8), otherwise their spring forces.
    """
    forces = None if wrench is None else forces_from_wrench(platform, pose, wrench)
    return axis_stiffness(stiffness(platform, pose, forces), "ray")
