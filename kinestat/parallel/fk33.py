"""Closed-form forward kinematics of the octahedral 3-3 platform, batched.

Base triangle O, P, Q; top triangle R, S, T; six legs O–R, O–S, P–S, P–T, Q–T, Q–R (the
thesis's ``L_or, L_os, L_ps, L_pt, L_qt, L_qr``, Vibhute 2011 Appendix B, after Griffis & Duffy
1989). Our own derivation, in the spirit of Griffis & Duffy's three spherical four-bars:

* Each top vertex is joined to two base vertices, so it lies on a circle about that base edge:
  ``R(θ_R) = c_R + ρ_R (cos θ_R n_R + sin θ_R z)``, ``n_R`` the in-plane normal of edge OQ
  pointing into the base triangle, z the base normal (S about OP, T about PQ likewise).
* The three top sides give three equations ``|U − V|² = d²``; with half-angle tangents
  ``x = tan(θ_R/2), y = tan(θ_S/2), z = tan(θ_T/2)`` each is
  ``A u²v² + B u² + C v² + D uv + E = 0`` (:func:`pair_coefficients`).
* Eliminating y (resultant of two quadratics) and then z (resultant of a quartic and a
  quadratic, written with power sums so it stays polynomial) leaves a degree-16 polynomial in x
  that is even: degree 8 in ``w = x²``. Each real root ``w ≥ 0`` gives ``x = ±√w``: a pose and
  its mirror image through the base plane. Hence up to 16 real assembly modes in 8 mirror pairs.
* θ_S and θ_T follow from the RS and TR equations (two candidates each; the pair that satisfies
  ST is kept), then a few Newton steps polish each pose and reverse kinematics verifies it.

The polynomial roots are the eigenvalues of companion matrices, stacked over the batch.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from kinestat.errors import InputError
from kinestat.parallel._fk_tolerances import COMBO_TOL, IMAG_TOL, SIG_TOL
from kinestat.parallel._refine import cross, refine_where
from kinestat.spatial.transforms import as_array

__all__ = [
    "MAX_SOLUTIONS",
    "LEGS_33",
    "triangle_frame",
    "pair_coefficients",
    "fk33_polynomial",
    "fk_33",
]

#: Upper bound on the number of real assembly modes of a 3-3 (and special 6-6) platform.
MAX_SOLUTIONS = 16

#: The equivalent 3-3 legs as (base vertex, top vertex) indices into (O, P, Q) and (R, S, T).
LEGS_33 = ((0, 0), (0, 1), (1, 1), (1, 2), (2, 2), (2, 0))


def triangle_frame(points) -> np.ndarray:
    """Frame (4, 4) of a triangle A, B, C: origin A, x toward B, z along (B − A) × (C − A)."""
    p = np.asarray(points, dtype=float)
    x = p[..., 1, :] - p[..., 0, :]
    z = cross(x, p[..., 2, :] - p[..., 0, :])
    x = x / np.sqrt(np.sum(x * x, axis=-1, keepdims=True))
    z = z / np.sqrt(np.sum(z * z, axis=-1, keepdims=True))
    y = cross(z, x)
    F = np.zeros(p.shape[:-2] + (4, 4))
    F[..., :3, 0], F[..., :3, 1], F[..., :3, 2] = x, y, z
    F[..., :3, 3] = p[..., 0, :]
    F[..., 3, 3] = 1.0
    return F


def _circle(a, b, third, la2, lb2):
    """Circle of a point at squared distances la2 from a and lb2 from b (planar a, b, third).

    Returns centre (..., 3), in-plane unit normal toward ``third`` (3,), radius² (...).
    """
    e = b - a
    d = np.linalg.norm(e)
    e = e / d
    s = (la2 - lb2 + d * d) / (2 * d)
    n = (third - a) - ((third - a) @ e) * e
    n = n / np.linalg.norm(n)
    return a + s[..., None] * e, n, la2 - s * s


def pair_coefficients(cu, nu, ru, cv, nv, rv, d2):
    """(A, B, C, D, E) of ``|U − V|² = d²`` in half-angle tangents u, v of two circle points.

    ``U = cu + ru (cos θu nu + sin θu z)``, likewise V; centres in the plane z = 0. Then
    ``K0 + K1 cu + K2 cv + K3 cu cv + K4 su sv = 0`` and, multiplied by (1+u²)(1+v²),
    ``A u²v² + B u² + C v² + D uv + E = 0``. Also returns K = (K0..K4) as the last item.
    """
    dc = cu - cv
    K0 = np.einsum("...i,...i->...", dc, dc) + ru * ru + rv * rv - d2
    K1 = 2 * ru * (dc @ nu)
    K2 = -2 * rv * (dc @ nv)
    K3 = -2 * ru * rv * float(nu @ nv)
    K4 = -2 * ru * rv
    A = K0 - K1 - K2 + K3
    B = K0 - K1 + K2 - K3
    C = K0 + K1 - K2 - K3
    D = 4 * K4
    E = K0 + K1 + K2 + K3
    return A, B, C, D, E, (K0, K1, K2, K3, K4)


def _setup(base_local: np.ndarray, top_sides2: np.ndarray, sq: np.ndarray):
    """Circles and pair equations of a 3-3 with base in the plane z = 0 (local frame)."""
    O, P, Q = base_local
    or2, os2, ps2, pt2, qt2, qr2 = np.moveaxis(sq, -1, 0)
    cR, nR, rR2 = _circle(O, Q, P, or2, qr2)
    cS, nS, rS2 = _circle(O, P, Q, os2, ps2)
    cT, nT, rT2 = _circle(P, Q, O, pt2, qt2)
    rad2 = np.stack([rR2, rS2, rT2], axis=-1)
    rR, rS, rT = (np.sqrt(np.maximum(r, 0.0)) for r in (rR2, rS2, rT2))
    rs2, st2, tr2 = top_sides2
    f1 = pair_coefficients(cR, nR, rR, cS, nS, rS, rs2)  # u = x (R), v = y (S)
    f3 = pair_coefficients(cS, nS, rS, cT, nT, rT, st2)  # u = y (S), v = z (T)
    f2 = pair_coefficients(cT, nT, rT, cR, nR, rR, tr2)  # u = z (T), v = x (R)
    circles = ((cR, nR, rR), (cS, nS, rS), (cT, nT, rT))
    return circles, rad2, f1, f2, f3


#: The resultant is sampled at the 9th roots of unity in w (its degree is 8); the coefficients
#: are real, so only the first five samples are computed and the rest are their conjugates.
_NFFT = 9
_W = np.exp(2j * np.pi * np.arange(5) / _NFFT)
_X = np.sqrt(_W)


def fk33_polynomial(f1, f2, f3) -> np.ndarray:
    """Coefficients (..., 9) of the degree-8 polynomial in ``w = x² = tan²(θ_R/2)``, ascending.

    ``f1(x, y)``, ``f2(z, x)``, ``f3(y, z)`` are the (A, B, C, D, E) tuples of the three pair
    equations. Step 1: ``G(x, z) = Res_y(f1, f3) = (u2v0 − u0v2)² − (u2v1 − u1v2)(u1v0 − u0v1)``
    (f1 = u2 y² + u1 y + u0, f3 = v2 y² + v1 y + v0), a quartic in z. Step 2: with
    ``f2 = a z² + b z + c`` and roots z1, z2,
    ``Res_z(f2, G) = a⁴ G(z1) G(z2) = Σ_{j≤k} g_j g_k a^(4−k) c^j q_(k−j)``, where
    ``q_m = a^m (z1^m + z2^m)`` are polynomial in a, b, c (Newton's identities). The result is
    even in x (mirror symmetry), a polynomial of degree 8 in w; it is evaluated at the 9th roots of
    unity in w and its coefficients recovered by FFT.
    """
    A1, B1, C1, D1, E1 = (np.asarray(v)[..., None] for v in f1[:5])
    A2, B2, C2, D2, E2 = (np.asarray(v)[..., None] for v in f2[:5])
    A3, B3, C3, D3, E3 = (np.asarray(v)[..., None] for v in f3[:5])
    w, x = _W, _X
    u2, u1, u0 = A1 * w + C1, D1 * x, B1 * w + E1
    # coefficients in z of P = u2 v0 − u0 v2, Q = u2 v1 − u1 v2, R = u1 v0 − u0 v1
    p0, p2 = u2 * E3 - u0 * B3, u2 * C3 - u0 * A3
    q0, q1, q2 = -u1 * B3, u2 * D3, -u1 * A3
    r0, r1, r2 = u1 * E3, -u0 * D3, u1 * C3
    g = (p0 * p0 - q0 * r0,
         -(q0 * r1 + q1 * r0),
         2 * p0 * p2 - (q0 * r2 + q1 * r1 + q2 * r0),
         -(q1 * r2 + q2 * r1),
         p2 * p2 - q2 * r2)
    a, b, c = A2 * w + B2, D2 * x, C2 * w + E2
    ab, ac, bb = a * b, a * c, b * b
    q = (1.0, -b, bb - 2 * ac, -bb * b + 3 * ab * c, bb * bb - 4 * ab * b * c + 2 * ac * ac)
    apow = (1.0, a, a * a, a * a * a, (a * a) * (a * a))
    cpow = (1.0, c, c * c, c * c * c, (c * c) * (c * c))
    res = 0.0
    for j in range(5):
        for k in range(j, 5):
            res = res + g[j] * g[k] * apow[4 - k] * cpow[j] * q[k - j]
    res = np.concatenate([res, np.conj(res[..., 4:0:-1])], axis=-1)
    return np.fft.fft(res, axis=-1).real / _NFFT


def _companion_eigvals(c: np.ndarray) -> np.ndarray:
    """Roots (..., n) of polynomials with ascending coefficients (..., n+1), leading nonzero."""
    n = c.shape[-1] - 1
    M = np.zeros(c.shape[:-1] + (n, n))
    M[..., np.arange(1, n), np.arange(n - 1)] = 1.0
    M[..., :, -1] = -c[..., :-1] / c[..., -1:]
    return np.linalg.eigvals(M)


def _root_angles(poly_w: np.ndarray, imag_tol: float = IMAG_TOL):
    """Fold angles θ_R ∈ [0, π] of the (nearly) real roots w ≥ 0 of P(w) (..., 9); NaN elsewhere.

    Roots with a small imaginary part are kept (a multiple root, e.g. several modes sharing
    θ_R, splits into a complex cluster); Newton polishing and reverse kinematics decide. Uses
    the reversed polynomial (roots 1/w) where the leading coefficient is the smaller end, so a
    root at infinity (θ_R = π) is not lost.
    """
    c = poly_w / np.max(np.abs(poly_w), axis=-1, keepdims=True)
    rev = np.abs(c[..., -1]) < np.abs(c[..., 0])
    cc = np.where(rev[..., None], c[..., ::-1], c)
    lead_ok = np.abs(cc[..., -1]) > 0
    cc = np.where(lead_ok[..., None], cc, 1.0)
    roots = _companion_eigvals(cc)
    real = (np.abs(roots.imag) <= imag_tol * (1 + np.abs(roots))) & (
        roots.real >= -imag_tol * (1 + np.abs(roots)))
    real &= lead_ok[..., None]
    r = np.sqrt(np.maximum(roots.real, 0.0))
    ang = np.where(rev[..., None], np.arctan2(1.0, r), np.arctan2(r, 1.0)) * 2.0
    return np.where(real, ang, np.nan)


def _solve_partner(K, c_fixed, s_fixed, fixed_is_u: bool):
    """Both angles θ of the partner point in ``K0 + K1 cu + K2 cv + K3 cu cv + K4 su sv = 0``.

    ``K`` are arrays (M,), the fixed point's cos/sin (M,); returns (M, 2).
    """
    K0, K1, K2, K3, K4 = K
    if fixed_is_u:
        alpha, beta, gamma = K2 + K3 * c_fixed, K4 * s_fixed, -(K0 + K1 * c_fixed)
    else:
        alpha, beta, gamma = K1 + K3 * c_fixed, K4 * s_fixed, -(K0 + K2 * c_fixed)
    phi = np.arctan2(beta, alpha)
    rr = np.hypot(alpha, beta)
    ratio = np.clip(gamma / np.where(rr > 0, rr, np.nan), -1.0, 1.0)
    da = np.arccos(ratio)
    return np.stack([phi + da, phi - da], axis=-1)


def _pair_residual(K, tu, tv):
    K0, K1, K2, K3, K4 = (k[:, None, None] for k in K)
    cu, su, cv, sv = np.cos(tu), np.sin(tu), np.cos(tv), np.sin(tv)
    return K0 + K1 * cu + K2 * cv + K3 * cu * cv + K4 * su * sv


def fk_33(base_tri, top_tri, lengths, *, tol: float = 1e-9, polish: int = 4):
    """All real assembly modes of a 3-3 platform, batched.

    Args:
        base_tri: (3, 3) base vertices O, P, Q in the base frame.
        top_tri: (3, 3) top vertices R, S, T in the top frame.
        lengths: (..., 6) leg lengths ``[or, os, ps, pt, qt, qr]``.
        tol: acceptance of a mode: every leg reproduced by reverse kinematics within ``tol``.
        polish: at most this many Newton steps for closed-form poses whose legs are off by more
            than ``tol / 10``.

    Returns:
        ``(poses, valid)``: poses (..., 16, 4, 4) of the top frame in the base frame (NaN where
        not valid) and the mask (..., 16) of verified, distinct real modes. Slots ``2i`` and
        ``2i+1`` hold a mirror pair (reflections of each other through the base plane).
    """
    base_tri = as_array(base_tri, shape_tail=(3, 3), name="base triangle")
    top_tri = as_array(top_tri, shape_tail=(3, 3), name="top triangle")
    L = as_array(lengths, shape_tail=(6,), name="3-3 leg lengths")
    if np.any(L < 0):
        raise InputError("3-3 leg lengths must be non-negative")
    base_pts = base_tri[[b for b, _ in LEGS_33]]
    top_pts = top_tri[[t for _, t in LEGS_33]]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        bi, qi, pose = _fk33_modes(base_tri, top_tri, L * L)
        Lf = L.reshape(-1, 6)[bi]
        pose, err = refine_where(base_pts, top_pts, Lf, pose, np.ones(len(bi), bool),
                                 0.1 * tol, iterations=polish)
    scale = float(np.linalg.norm(base_tri[1] - base_tri[0]))
    poses, valid, _ = assemble_modes(L.shape[:-1], bi, qi, pose, err, tol, base_tri, top_tri,
                                     scale)
    return poses, valid


def mirror_matrices(base_tri, top_tri) -> tuple[np.ndarray, np.ndarray]:
    """Reflections (4, 4) through the base triangle's plane and through the top triangle's plane.

    ``Mb @ T @ Mt`` is the mirror image of the pose T through the base plane: it reflects every
    top point through the base plane, so every leg keeps its length.
    """
    return _mirrors(tuple(np.asarray(base_tri, float).ravel()),
                    tuple(np.asarray(top_tri, float).ravel()))


@lru_cache(maxsize=64)
def _mirrors(base_key: tuple, top_key: tuple) -> tuple[np.ndarray, np.ndarray]:
    D = np.diag([1.0, 1.0, -1.0, 1.0])
    Fb = triangle_frame(np.array(base_key).reshape(3, 3))
    Ft = triangle_frame(np.array(top_key).reshape(3, 3))
    Mb, Mt = Fb @ D @ np.linalg.inv(Fb), Ft @ D @ np.linalg.inv(Ft)
    Mb.flags.writeable = Mt.flags.writeable = False
    return Mb, Mt


def pose_signature(pose: np.ndarray, scale: float) -> np.ndarray:
    """A 9-vector per pose (translation/scale, x and y axes): equal poses, equal signatures."""
    return np.concatenate([pose[..., :3, 3] / scale, pose[..., :3, 0], pose[..., :3, 1]],
                          axis=-1)


def first_occurrences(sig: np.ndarray, valid: np.ndarray, tol: float = SIG_TOL) -> np.ndarray:
    """Mask (..., K) of valid entries whose signature does not repeat an earlier valid one."""
    sig = np.where(valid[..., None], sig, 0.0)
    n2 = np.sum(sig * sig, axis=-1)
    d2 = n2[..., :, None] + n2[..., None, :] - 2.0 * (sig @ np.swapaxes(sig, -1, -2))
    K = sig.shape[-2]
    close = (d2 < tol * tol) & valid[..., :, None] & valid[..., None, :]
    close &= np.tril(np.ones((K, K), bool), -1)
    return valid & ~np.any(close, axis=-1)


def assemble_modes(batch_shape, bi, qi, pose, err, tol, base_tri, top_tri, scale):
    """Distinct verified modes in 16 slots: mode k in slot 2k, its mirror image in slot 2k+1.

    ``bi, qi, pose, err`` are the compressed candidates (batch index, candidate index 0..31,
    refined pose, leg error). Returns ``(poses (..., 16, 4, 4) NaN-filled, valid, residual)``.
    """
    n = int(np.prod(batch_shape, dtype=int))
    ok = err <= tol
    cand = np.full((n, _NCAND, 4, 4), np.nan)
    cvalid = np.zeros((n, _NCAND), bool)
    cerr = np.full((n, _NCAND), np.inf)
    cand[bi[ok], qi[ok]] = pose[ok]
    cvalid[bi[ok], qi[ok]] = True
    cerr[bi[ok], qi[ok]] = err[ok]
    keep = first_occurrences(pose_signature(cand, scale), cvalid)
    rank = np.cumsum(keep, axis=-1) - 1
    keep &= rank < MAX_SOLUTIONS // 2
    b, q = np.nonzero(keep)
    slot = 2 * rank[b, q]
    Mb, Mt = mirror_matrices(base_tri, top_tri)
    out = np.full((n, MAX_SOLUTIONS, 4, 4), np.nan)
    valid = np.zeros((n, MAX_SOLUTIONS), bool)
    res = np.full((n, MAX_SOLUTIONS), np.inf)
    out[b, slot] = cand[b, q]
    out[b, slot + 1] = Mb @ cand[b, q] @ Mt
    valid[b, slot] = valid[b, slot + 1] = True
    res[b, slot] = res[b, slot + 1] = cerr[b, q]
    # a mode in the base plane is its own mirror image (or another mode's): keep it once
    valid = first_occurrences(pose_signature(out, scale), valid)
    out[~valid] = np.nan
    res[~valid] = np.inf
    shape = tuple(batch_shape)
    return (out.reshape(shape + (MAX_SOLUTIONS, 4, 4)), valid.reshape(shape + (MAX_SOLUTIONS,)),
            res.reshape(shape + (MAX_SOLUTIONS,)))


#: Candidates per leg-length set: 8 roots × 4 (θ_S, θ_T) combinations, θ_R ≥ 0 only.
_NCAND = 32
#: A (θ_S, θ_T) combination is a candidate when it satisfies the third pair equation to
#: ``COMBO_TOL`` (nondimensional; the best combination of each root is always a candidate).


@lru_cache(maxsize=64)
def _geometry(base_key: tuple, top_key: tuple):
    """Constant geometry of a 3-3 (cached): frames, nondimensional triangles, scale."""
    base_tri = np.array(base_key).reshape(3, 3)
    top_tri = np.array(top_key).reshape(3, 3)
    Fb, Ft = triangle_frame(base_tri), triangle_frame(top_tri)
    scale = float(np.linalg.norm(base_tri[1] - base_tri[0]))
    # triangles in their own frames, nondimensional
    base_loc = (base_tri - Fb[:3, 3]) @ Fb[:3, :3] / scale
    top_loc = (top_tri - Ft[:3, 3]) @ Ft[:3, :3] / scale
    top_sides2 = np.array([np.sum((top_loc[i] - top_loc[j]) ** 2)
                           for i, j in ((0, 1), (1, 2), (2, 0))])
    out = (Fb, np.linalg.inv(Ft), scale, base_loc, top_sides2)
    for a in out:
        if isinstance(a, np.ndarray):
            a.flags.writeable = False
    return out


def _fk33_modes(base_tri, top_tri, sq):
    """Closed-form candidate modes with θ_R ≥ 0, compressed over the flattened batch.

    Returns ``(bi, qi, poses)``: batch index (into ``sq.reshape(-1, 6)``), candidate index
    ``4 * root + combination`` (0..31) and the pose (M, 4, 4) of every candidate.
    """
    sq = sq.reshape(-1, 6)
    Fb, Ft_inv, scale, base_loc, top_sides2 = _geometry(
        tuple(np.asarray(base_tri, float).ravel()), tuple(np.asarray(top_tri, float).ravel()))
    circles, rad2, f1, f2, f3 = _setup(base_loc, top_sides2, sq / scale**2)
    feasible = np.all(rad2 >= -1e-12, axis=-1) & np.all(np.isfinite(sq), axis=-1)
    poly_w = fk33_polynomial(f1, f2, f3)
    bad = ~np.all(np.isfinite(poly_w), axis=-1) | (np.max(np.abs(poly_w), axis=-1) == 0)
    poly_w = np.where(bad[..., None], 1.0, poly_w)
    thR = _root_angles(poly_w)  # (n, 8)
    cand = np.isfinite(thR) & (feasible & ~bad)[:, None]
    bi, ri = np.nonzero(cand)
    th = thR[bi, ri]
    cR, sR = np.cos(th), np.sin(th)
    thS = _solve_partner([k[bi] for k in f1[5]], cR, sR, fixed_is_u=True)  # (M, 2)
    thT = _solve_partner([k[bi] for k in f2[5]], cR, sR, fixed_is_u=False)  # (M, 2)
    res = np.abs(_pair_residual([k[bi] for k in f3[5]], thS[:, :, None], thT[:, None, :]))
    res = np.where(np.isfinite(res), res, np.inf).reshape(-1, 4)
    take = (res <= COMBO_TOL) | (res == res.min(axis=-1, keepdims=True))
    take &= np.isfinite(res)
    m, c = np.nonzero(take)
    bi, qi = bi[m], 4 * ri[m] + c
    th, thS, thT = th[m], thS[m, c // 2], thT[m, c % 2]
    zhat = np.array([0.0, 0.0, 1.0])
    pts = []
    for (cc, n, r), t in zip(circles, (th, thS, thT), strict=True):
        pts.append(cc[bi] + r[bi, None] * (np.cos(t)[:, None] * n + np.sin(t)[:, None] * zhat))
    tri = np.stack(pts, axis=-2)  # (M, 3, 3) R, S, T in the local base frame
    finite = np.all(np.isfinite(tri), axis=(-1, -2))
    bi, qi, tri = bi[finite], qi[finite], tri[finite]
    # to the base frame, model units; the pose maps top-frame coordinates (Ft: top triangle frame)
    tri = (scale * tri) @ Fb[:3, :3].T + Fb[:3, 3]
    pose = triangle_frame(tri) @ Ft_inv
    return bi, qi, pose
