"""Compiled (Numba) pieces of one control cycle: the vernier's cos/sin tables
(:func:`vernier_tables_kernel`, :func:`kinestat.control.vernier.vernier_tables`'s arithmetic
value for value), the envelope's prediction around the platform's kernel
(:func:`predict_kernel`, equal to its NumPy wrapping to rounding) and the curvature of the
measured tip path (:func:`kinestat.control.contact_estimate.path_curvature` for one path, the
follow task's estimator). The circle fit's least squares is solved by Householder QR of the
(N, 3) design matrix instead of NumPy's SVD-based ``lstsq``: for a full-rank matrix both give
the least-squares solution, equal to rounding (relative ~ condition number × 1e-16). A design
matrix near rank deficiency (where ``lstsq`` would return its minimum-norm solution) is left to
the NumPy formulation (the kernel says so). Compiled on first use and cached on disk
(``cache=True``, in ``__pycache__``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.parallel._kinestatic_kernels import singular_ratio6, solve6
from kinestat.parallel._stiffness_kernels import pinned_tip_step_one
from kinestat.serial.puma762._cycle_kernels import grid_nearest, pose_one, reverse_select_one
from kinestat.spatial._elimination import eliminate

_OPTS = {"cache": True, "fastmath": False, "nogil": True, "error_model": "numpy"}

__all__ = ["base_twist_kernel", "command_clear_kernel", "measurement_clear_kernel",
           "path_curvature_kernel", "predict_kernel", "puma_counts_kernel", "slide_kernel",
           "vernier_tables_kernel"]

_PI = math.pi
_TWO_PI = 2.0 * math.pi
_DEG = math.pi / 180.0  # numpy.radians(x) is x * (π/180)
_PER_RAD = 180.0 / math.pi  # numpy.degrees(x) is x * (180/π)


@nb.njit(**_OPTS)
def vernier_tables_kernel(c0, off, n1, n2, n3, n4, n5, now3, coupling, res, axis_offset):
    """The PUMA 762 vernier's cos/sin tables (:func:`kinestat.control.vernier.vernier_tables`)
    for the counts ``c0`` (6,) int64 and the grid rows ``off`` (rows, 6) int64
    (:func:`~kinestat.control.vernier.grid_rows`: axes 1-3's values in the first rows, the
    wrist's ``n4 n5`` combinations in the last): each candidate's count → axis-5 residual of
    the 4 → 5 compensation (``now3`` the current axis-4 count, ``coupling``) → degrees
    (``res``, (6,)) → radians → joint angle (``axis_offset``, joint 1 wrapped to [−π, π)) →
    cos, sin, the same operations in the same order as the NumPy formulation.

    Returns ``(cs1 (n1, 2), cs2 (n2, 2), cs3 (n3, 2), cs4 (n4, 2), cs5 (n4, n5, 2), cs6 (2,))``.
    """
    rows = off.shape[0]
    q = np.empty((rows, 6))
    for r in range(rows):
        kappa = coupling * (float(c0[3] + off[r, 3]) - now3)
        a = -kappa
        rnd = (1.0 if a > 0.0 else (-1.0 if a < 0.0 else 0.0)) * math.floor(abs(a) + 0.5)
        for j in range(6):
            phys = float(c0[j] + off[r, j])
            if j == 4:
                phys += float(np.int64(rnd)) + kappa
            v = phys * res[j] * _DEG - axis_offset[j]
            if j == 0:
                v = (v + _PI) % _TWO_PI - _PI
            q[r, j] = v
    cs1 = np.empty((n1, 2))
    cs2 = np.empty((n2, 2))
    cs3 = np.empty((n3, 2))
    for i in range(n1):
        cs1[i, 0], cs1[i, 1] = math.cos(q[i, 0]), math.sin(q[i, 0])
    for i in range(n2):
        cs2[i, 0], cs2[i, 1] = math.cos(q[i, 1]), math.sin(q[i, 1])
    for i in range(n3):
        cs3[i, 0], cs3[i, 1] = math.cos(q[i, 2]), math.sin(q[i, 2])
    w0 = rows - n4 * n5
    cs4 = np.empty((n4, 2))
    cs5 = np.empty((n4, n5, 2))
    for i4 in range(n4):
        cs4[i4, 0], cs4[i4, 1] = math.cos(q[w0 + i4 * n5, 3]), math.sin(q[w0 + i4 * n5, 3])
        for i5 in range(n5):
            v = q[w0 + i4 * n5 + i5, 4]
            cs5[i4, i5, 0], cs5[i4, i5, 1] = math.cos(v), math.sin(v)
    cs6 = np.empty(2)
    cs6[0], cs6[1] = math.cos(q[0, 5]), math.sin(q[0, 5])
    return cs1, cs2, cs3, cs4, cs5, cs6

@nb.njit(**_OPTS)
def puma_counts_kernel(p, z, x, p6, q_now, axis_offset, lo, hi, res, coupling, now3, off, n1,
                       n2, n3, n4, n5, centre, w_along, w_lat, w_tilt, counts, q_new, T):
    """The PUMA 762's move onto a target in one call (one dispatch): the axis angles of the
    least-motion solution within ``[lo, hi]`` (:func:`~kinestat.serial.puma762._cycle_kernels.
    reverse_select_one`), their counts (``round_half_away(degrees(axis) / res)``), the
    vernier's grid search around them (:func:`vernier_tables_kernel`,
    :func:`~kinestat.serial.puma762._cycle_kernels.grid_nearest`; the grid rows ``off`` and
    sizes ``n1..n5`` of :func:`kinestat.control.vernier.grid_rows`, ``centre`` its centre
    index), the chosen counts into ``counts`` (6,) int64, their joint angles into ``q_new``
    (6,) (``radians(counts · res) − axis_offset``, joint 1 wrapped to [−π, π)) and the flange
    pose ``F_6T`` into ``T`` (4, 4) (:func:`~kinestat.serial.puma762._cycle_kernels.pose_one`):
    :func:`kinestat.control.controller._solve_counts`, ``axis_counts_to_q`` and
    ``_flange_pose`` in the same operations and order (the cos and sin are the kernel's).
    ``p, z, x`` the target's tool point, S6 and a67, ``p6`` the tool point in frame 6,
    ``q_now`` (6,) the present joint angles, ``now3`` the present axis-4 count.

    Returns ``(ok, along)``: False where the reverse analysis or the selection fails (the
    caller runs the NumPy path for its error), ``along`` the chosen tool point's offset from
    the target along S6 (mm).
    """
    axis = np.empty(6)
    if not reverse_select_one(p, z, x, p6, q_now, axis_offset, lo, hi, axis):
        return False, 0.0
    c0 = np.empty(6, dtype=np.int64)
    for j in range(6):
        a = axis[j] * _PER_RAD / res[j]
        sgn = 1.0 if a > 0.0 else (-1.0 if a < 0.0 else 0.0)
        c0[j] = np.int64(sgn * math.floor(abs(a) + 0.5))
    cs1, cs2, cs3, cs4, cs5, cs6 = vernier_tables_kernel(c0, off, n1, n2, n3, n4, n5, now3,
                                                         coupling, res, axis_offset)
    k, along, _ = grid_nearest(cs1, cs2, cs3, cs4, cs5, cs6, p6, p, z, w_along, w_lat, w_tilt,
                               centre)
    i5 = k % n5
    i4 = (k // n5) % n4
    i3 = (k // (n5 * n4)) % n3
    i2 = (k // (n5 * n4 * n3)) % n2
    i1 = k // (n5 * n4 * n3 * n2)
    w0 = off.shape[0] - n4 * n5
    counts[0] = c0[0] + off[i1, 0]
    counts[1] = c0[1] + off[i2, 1]
    counts[2] = c0[2] + off[i3, 2]
    counts[3] = c0[3] + off[w0 + i4 * n5, 3]
    counts[4] = c0[4] + off[w0 + i4 * n5 + i5, 4]
    counts[5] = c0[5]
    cs = np.empty((6, 2))
    for j in range(6):
        v = float(counts[j]) * res[j] * _DEG - axis_offset[j]
        if j == 0:
            v = (v + _PI) % _TWO_PI - _PI
        q_new[j] = v
        cs[j, 0], cs[j, 1] = math.cos(v), math.sin(v)
    pose_one(cs, T)
    return True, along


#: the relative margin by which a value must lie inside its limit for the compiled pre-checks
#: to call it clear (:func:`measurement_clear_kernel`, :func:`command_clear_kernel`): a value
#: nearer its limit goes to the checks in Python, whatever the rounding
CLEAR_MARGIN = 1e-9


@nb.njit(**_OPTS)
def _inside(v, lim):
    """``|v|`` at least ``CLEAR_MARGIN`` (relative) inside ``lim`` (False for NaN)."""
    return abs(v) <= lim - CLEAR_MARGIN * (1.0 + abs(lim))


@nb.njit(**_OPTS)
def _motion_clear(T, H, c, hc, mr, rot_min):
    """The top pose ``T`` (4, 4) clearly inside the motion ranges ``mr`` (6,): its rotation
    from home (``H`` (3, 3) the home rotation) bounded by the trace's angle below the least
    rotation range ``rot_min`` (degrees) by more than 1e-6°, and its centroid's displacement
    (``c`` (3,) the top's centroid, ``hc`` (3,) its home position) inside x, y, z
    (:func:`kinestat.control.envelope.check_motion`'s shortcut); False otherwise (the checks
    in Python then decide)."""
    tr = 0.0
    for r in range(3):
        tr += T[r, 0] * H[r, 0] + T[r, 1] * H[r, 1] + T[r, 2] * H[r, 2]
    cth = min(1.0, max(-1.0, (tr - 1.0) / 2.0))
    angle = math.degrees(math.acos(cth))
    if not angle + 1e-6 < rot_min - CLEAR_MARGIN * (1.0 + rot_min):
        return False
    for r in range(3):
        m = (T[r, 0] * c[0] + T[r, 1] * c[1] + T[r, 2] * c[2] + T[r, 3]) - hc[r]
        if not _inside(m, mr[r]):
            return False
    return True


@nb.njit(**_OPTS)
def measurement_clear_kernel(wrench, lengths, free_lengths, T, H, c, hc, mr, rot_min,
                             max_load, max_deflection):
    """True when a measurement is clearly inside the envelope
    (:func:`kinestat.control.envelope.check_measurement` finds nothing, with a margin): the
    wrench (6,) and leg lengths (6,) finite, the force under ``max_load``, every deflection
    ``l − l0`` under ``max_deflection`` and the top pose ``T`` inside the motion ranges
    (:func:`_motion_clear`). False does not mean a violation: the checks in Python decide."""
    for i in range(6):
        if not (math.isfinite(wrench[i]) and math.isfinite(lengths[i])):
            return False
    f = math.sqrt(wrench[0] * wrench[0] + wrench[1] * wrench[1] + wrench[2] * wrench[2])
    if not _inside(f, max_load):
        return False
    for i in range(6):
        if not _inside(lengths[i] - free_lengths[i], max_deflection):
            return False
    return _motion_clear(T, H, c, hc, mr, rot_min)


@nb.njit(**_OPTS)
def command_clear_kernel(a, now, has_now, lo, hi, max_step, force, defl, T, has_pred, has_top,
                         H, c, hc, mr, rot_min, max_load, max_deflection):
    """True when a command is clearly inside the envelope
    (:func:`kinestat.control.envelope.check_command` finds nothing, with a margin): the axis
    angles ``a`` (6,, degrees) finite and inside ``[lo, hi]``, each within ``max_step`` of
    ``now`` (when ``has_now``), and (when ``has_pred``) the predicted force (3,) and
    deflections (6,) finite and under the load and deflection limits and (when ``has_top``)
    the predicted top pose ``T`` inside the motion ranges. False does not mean a violation:
    the checks in Python decide."""
    for j in range(6):
        if not math.isfinite(a[j]):
            return False
        if not (lo[j] + CLEAR_MARGIN * (1.0 + abs(lo[j])) <= a[j]
                <= hi[j] - CLEAR_MARGIN * (1.0 + abs(hi[j]))):
            return False
        if has_now and not _inside(a[j] - now[j], max_step):
            return False
    if not has_pred:
        return True
    for i in range(6):
        if not math.isfinite(defl[i]):
            return False
        if not _inside(defl[i], max_deflection):
            return False
    for i in range(3):
        if not math.isfinite(force[i]):
            return False
    f = math.sqrt(force[0] * force[0] + force[1] * force[1] + force[2] * force[2])
    if not _inside(f, max_load):
        return False
    return _motion_clear(T, H, c, hc, mr, rot_min) if has_top else True


#: smallest |R_kk| / max |R_jj| of the QR factor the kernel solves with (else: NumPy's lstsq)
RANK_TOL = 1e-10


@nb.njit(**_OPTS)
def _householder_lstsq(M, b, coef):
    """Least squares ``min |M coef − b|`` for ``M`` (n, 3) by Householder QR (``M`` and ``b``
    overwritten); False when ``R``'s smallest diagonal is below :data:`RANK_TOL` of its
    largest."""
    n = M.shape[0]
    for k in range(3):
        s = 0.0
        for i in range(k, n):
            s += M[i, k] * M[i, k]
        nrm = math.sqrt(s)
        if nrm == 0.0:
            return False
        alpha = -nrm if M[k, k] >= 0.0 else nrm
        v = np.empty(n - k)
        for i in range(k, n):
            v[i - k] = M[i, k]
        v[0] -= alpha
        vv = 0.0
        for i in range(n - k):
            vv += v[i] * v[i]
        if vv > 0.0:
            for j in range(k, 3):
                d = 0.0
                for i in range(k, n):
                    d += v[i - k] * M[i, j]
                f = 2.0 * d / vv
                for i in range(k, n):
                    M[i, j] -= f * v[i - k]
            d = 0.0
            for i in range(k, n):
                d += v[i - k] * b[i]
            f = 2.0 * d / vv
            for i in range(k, n):
                b[i] -= f * v[i - k]
    rmax = max(abs(M[0, 0]), abs(M[1, 1]), abs(M[2, 2]))
    if min(abs(M[0, 0]), abs(M[1, 1]), abs(M[2, 2])) <= RANK_TOL * rmax:
        return False
    for k in range(2, -1, -1):
        s = b[k]
        for j in range(k + 1, 3):
            s -= M[k, j] * coef[j]
        coef[k] = s / M[k, k]
    return True


@nb.njit(**_OPTS)
def path_curvature_kernel(points, tip, normal, tangent, min_span):
    """The signed curvature of the tip path (:func:`~kinestat.control.contact_estimate.
    path_curvature`'s formulation: the points and the tip in the plane of ``tangent`` and
    ``normal`` through ``tip``, the circle ``A (x² + y²) + B x − y + D = 0`` fitted in the
    least-squares sense, ``κ = −2A / sqrt(max(B² + 1 − 4AD, 1e-12))``, 0 for a span below
    ``min_span`` or a sagitta ``|κ| span²/8`` below twice the RMS residual).

    Args:
        points: (N, 3), N ≥ 3, the earlier tips; tip, normal, tangent: (3,).

    Returns ``(κ, ok)``; ``ok`` False when the fit's matrix is near rank deficient (the
    caller then runs the NumPy formulation).
    """
    n = points.shape[0] + 1
    x = np.empty(n)
    y = np.empty(n)
    for i in range(n - 1):
        d0 = points[i, 0] - tip[0]
        d1 = points[i, 1] - tip[1]
        d2 = points[i, 2] - tip[2]
        x[i] = d0 * tangent[0] + d1 * tangent[1] + d2 * tangent[2]
        y[i] = d0 * normal[0] + d1 * normal[1] + d2 * normal[2]
    x[n - 1] = 0.0
    y[n - 1] = 0.0
    xmin = x[0]
    xmax = x[0]
    for i in range(1, n):
        xmin = min(xmin, x[i])
        xmax = max(xmax, x[i])
    span = xmax - xmin
    if span < min_span:
        return 0.0, True
    M = np.empty((n, 3))
    b = np.empty(n)
    for i in range(n):
        M[i, 0] = x[i] * x[i] + y[i] * y[i]
        M[i, 1] = x[i]
        M[i, 2] = 1.0
        b[i] = y[i]
    coef = np.empty(3)
    if not _householder_lstsq(M, b, coef):
        return 0.0, False
    A, B, D = coef[0], coef[1], coef[2]
    kappa = -2.0 * A / math.sqrt(max(B * B + 1.0 - 4.0 * A * D, 1e-12))
    ss = 0.0
    for i in range(n):
        r = y[i] - (A * (x[i] * x[i] + y[i] * y[i]) + B * x[i] + D)
        ss += r * r
    if abs(kappa) * span * span / 8.0 < 2.0 * math.sqrt(ss / n):
        return 0.0, True
    return kappa, True


@nb.njit(**_OPTS)
def _base_pose(Tn, mount):
    """The top three rows (3, 4) of ``Tn @ mount``: the platform base's pose for the flange
    pose ``Tn`` (4, 4), each entry summed left to right."""
    TB = np.empty((3, 4))
    for r in range(3):
        for c in range(4):
            TB[r, c] = (Tn[r, 0] * mount[0, c] + Tn[r, 1] * mount[1, c]
                        + Tn[r, 2] * mount[2, c] + Tn[r, 3] * mount[3, c])
    return TB


@nb.njit(**_OPTS)
def predict_kernel(Tn, mount, tip_F, p, base_R, f_point, B, P_top, T, K, flange, lengths,
                   free_lengths, force, defl, tip_motion, top):
    """:func:`kinestat.control.predict.predict`'s compiled path for one measurement and one
    new flange pose ``Tn`` (4, 4), in one call: the base's new pose ``Tn · mount``, the pinned
    tip's offset ``u`` in the new base frame and the external force ``F = −R_Bᵀ f_point`` on
    the tip (base frame), the platform's response
    (:func:`kinestat.parallel._stiffness_kernels.pinned_tip_step_one`), then the force on the
    workpiece ``−R_new (F + δF)`` into ``force`` (3,), the deflections ``l − l0 + δl`` into
    ``defl`` (6,), the flange-carried tip point's motion into ``tip_motion`` (3,) and the moved
    top pose into ``top`` (4, 4). ``tip_F``/``p`` (3,) the measured tip (fixed/base frame),
    ``flange`` (4, 4) the measured flange pose, ``B``/``P_top`` (6, 3) the platform's points,
    ``T`` the measured top pose, ``K`` its stiffness (axis order), ``lengths``/``free_lengths``
    (6,). False when the platform kernel meets a singular matrix (outputs then unset)."""
    TB = _base_pose(Tn, mount)
    u = np.empty(3)
    F = np.empty(3)
    for j in range(3):
        u[j] = ((tip_F[0] - TB[0, 3]) * TB[0, j] + (tip_F[1] - TB[1, 3]) * TB[1, j]
                + (tip_F[2] - TB[2, 3]) * TB[2, j]) - p[j]
        F[j] = -(f_point[0] * base_R[0, j] + f_point[1] * base_R[1, j]
                 + f_point[2] * base_R[2, j])
    dF = np.empty(3)
    D = np.empty(6)
    dl = np.empty(6)
    if not pinned_tip_step_one(B, P_top, T, K, p, u, F, dF, D, dl, top):
        return False
    for r in range(3):
        force[r] = -(TB[r, 0] * (F[0] + dF[0]) + TB[r, 1] * (F[1] + dF[1])
                     + TB[r, 2] * (F[2] + dF[2]))
    for i in range(6):
        defl[i] = (lengths[i] - free_lengths[i]) + dl[i]
    loc = np.empty(3)
    for j in range(3):  # the tip in the measured flange frame
        loc[j] = ((tip_F[0] - flange[0, 3]) * flange[0, j]
                  + (tip_F[1] - flange[1, 3]) * flange[1, j]
                  + (tip_F[2] - flange[2, 3]) * flange[2, j])
    for r in range(3):
        tip_motion[r] = (Tn[r, 0] * loc[0] + Tn[r, 1] * loc[1] + Tn[r, 2] * loc[2]
                         + Tn[r, 3]) - tip_F[r]
    return True


@nb.njit(**_OPTS)
def slide_kernel(Tn, mount, tip_F, p, base_R, est, K, C, push, has_push, out):
    """:func:`kinestat.control.predict.sliding_push`'s first-order frictionless slide for one
    measurement and one new flange pose ``Tn`` (4, 4), in one call: ``out[0]`` the force
    magnitude ``f + δf`` (N) after the move and, when ``has_push``, ``out[1]`` its rate
    ``d(f + δf)/ds`` (N/mm) for a further translation ``s`` of the flange along ``push`` (3,,
    fixed frame). With ``F = −R_Bᵀ est`` the external force on the tip (base frame),
    ``n' = −R_newᵀ est / f`` the normal in the new base frame, ``u`` the pinned tip's motion,
    ``M = I + (K⁻¹ Z)[3:] − [p]× (K⁻¹ Z)[:3]`` with ``Z = [0; [F]×]`` and ``t1, t2`` the tangent
    plane of ``n'``: ``[M t1, M t2, −C n'] [τ; δf] = C (f n' − F) − M u`` (and ``M R_newᵀ push``
    as a second right-hand side). ``tip_F``/``p`` (3,) the measured tip (fixed/base frame),
    ``base_R`` (3, 3) the measured base rotation, ``est`` (3,) the measured force on the
    workpiece (fixed frame), ``K`` (6, 6) the stiffness (axis order), ``C`` (3, 3) the tip's
    compliance (base frame). Returns 1, 0 out of contact (``f`` ≤ 1e-9 N: ``out`` unset) or
    −1 where an elimination meets a zero pivot (the NumPy formulation then raises)."""
    f = math.sqrt(est[0] * est[0] + est[1] * est[1] + est[2] * est[2])
    if not f > 1e-9:
        return 0
    TB = _base_pose(Tn, mount)
    F = np.empty(3)
    u = np.empty(3)
    n = np.empty(3)
    for j in range(3):
        F[j] = -(base_R[0, j] * est[0] + base_R[1, j] * est[1] + base_R[2, j] * est[2])
        u[j] = (TB[0, j] * (tip_F[0] - TB[0, 3]) + TB[1, j] * (tip_F[1] - TB[1, 3])
                + TB[2, j] * (tip_F[2] - TB[2, 3])) - p[j]
        n[j] = (TB[0, j] * (-est[0] / f) + TB[1, j] * (-est[1] / f)
                + TB[2, j] * (-est[2] / f))
    # K⁻¹ Z, Z = [0; [F]×] (6, 3)
    A = np.zeros((6, 9))
    for r in range(6):
        for c in range(6):
            A[r, c] = K[r, c]
    A[3, 7], A[3, 8] = -F[2], F[1]
    A[4, 6], A[4, 8] = F[2], -F[0]
    A[5, 6], A[5, 7] = -F[1], F[0]
    if not eliminate(A, 6, 0.0, None) > 0.0:
        return -1
    M = np.empty((3, 3))  # I + X[3:] − [p]× X[:3], X = K⁻¹ Z
    for c in range(3):
        x0, x1, x2 = A[0, 6 + c], A[1, 6 + c], A[2, 6 + c]
        M[0, c] = A[3, 6 + c] - (-p[2] * x1 + p[1] * x2)
        M[1, c] = A[4, 6 + c] - (p[2] * x0 - p[0] * x2)
        M[2, c] = A[5, 6 + c] - (-p[1] * x0 + p[0] * x1)
        M[c, c] += 1.0
    k = 0  # the normal's smallest component (numpy.argmin: the first of equals)
    for j in range(1, 3):
        if abs(n[j]) < abs(n[k]):
            k = j
    e = np.zeros(3)
    e[k] = 1.0
    t1 = np.empty(3)
    t1[0] = n[1] * e[2] - n[2] * e[1]
    t1[1] = n[2] * e[0] - n[0] * e[2]
    t1[2] = n[0] * e[1] - n[1] * e[0]
    s = math.sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2])
    for j in range(3):
        t1[j] = t1[j] / s
    t2 = np.empty(3)
    t2[0] = n[1] * t1[2] - n[2] * t1[1]
    t2[1] = n[2] * t1[0] - n[0] * t1[2]
    t2[2] = n[0] * t1[1] - n[1] * t1[0]
    pb = np.empty(3)  # R_newᵀ push
    for j in range(3):
        pb[j] = TB[0, j] * push[0] + TB[1, j] * push[1] + TB[2, j] * push[2]
    L = np.empty((3, 5))
    for r in range(3):
        L[r, 0] = M[r, 0] * t1[0] + M[r, 1] * t1[1] + M[r, 2] * t1[2]
        L[r, 1] = M[r, 0] * t2[0] + M[r, 1] * t2[1] + M[r, 2] * t2[2]
        L[r, 2] = -(C[r, 0] * n[0] + C[r, 1] * n[1] + C[r, 2] * n[2])
        L[r, 3] = ((C[r, 0] * (f * n[0] - F[0]) + C[r, 1] * (f * n[1] - F[1])
                    + C[r, 2] * (f * n[2] - F[2]))
                   - (M[r, 0] * u[0] + M[r, 1] * u[1] + M[r, 2] * u[2]))
        L[r, 4] = M[r, 0] * pb[0] + M[r, 1] * pb[1] + M[r, 2] * pb[2]
    if not eliminate(L, 3, 0.0, None) > 0.0:
        return -1
    out[0] = f + L[2, 3]
    if has_push:
        out[1] = L[2, 4]
    return 1


@nb.njit(**_OPTS)
def _rt3(R, x, out, o):
    """``out[o:o+3] = Rᵀ x`` for the (3, 3) block ``R`` and the 3-vector ``x``."""
    for i in range(3):
        out[o + i] = R[0, i] * x[0] + R[1, i] * x[1] + R[2, i] * x[2]


@nb.njit(**_OPTS)
def _cross_into(a, ao, b, bo, out, o):
    """``out[o:o+3] = a[ao:ao+3] × b[bo:bo+3]``."""
    a0, a1, a2 = a[ao], a[ao + 1], a[ao + 2]
    b0, b1, b2 = b[bo], b[bo + 1], b[bo + 2]
    out[o] = a1 * b2 - a2 * b1
    out[o + 1] = a2 * b0 - a0 * b2
    out[o + 2] = a0 * b1 - a1 * b0


@nb.njit(**_OPTS)
def base_twist_kernel(TB, K, tip, normal, omega, travel, dlam, max_correction, tangential_factor,
                      friction, slip, use_slip, hold_f, hold_w, use_hold, k_tol, in_tol, out):
    """The follow law's base twist (:func:`kinestat.control.follow._base_twist_numpy`, the same
    formulas in the same order, each ``K⁻¹ b`` by :func:`~kinestat.parallel.
    _kinestatic_kernels.solve6`): T = T_f − K⁻¹ W_c Δλ with the compliance part scaled to move
    the tip by at most ``max_correction`` (``tangential_factor`` times it along the surface),
    the friction cone's edge for a sliding tip (``use_slip``: ``slip`` (3,), ``friction``) and
    the sliding hold (``use_hold``: the held force ``hold_f`` turning by ``hold_w``), into
    ``out`` (6,), axis order ``[ω; v_O0]`` in the platform base frame. ``TB`` (4, 4) the base
    pose, ``K`` (6, 6) its loaded stiffness; ``tip``, ``normal``, ``omega``, ``travel`` (3,),
    fixed frame.

    The checks of :func:`~kinestat.parallel.kinestatic.compose_twist_line` are made with its
    tolerances (``k_tol``: K regular, its Jacobi ratio above twice it; ``in_tol``: the wrench
    change along W, the twist of freedom reciprocal to W). Returns False (``out`` unset) where
    one fails or a solve meets a zero pivot: the caller then runs the NumPy formulation, which
    raises its message.
    """
    if not singular_ratio6(K) > 2.0 * k_tol:
        return False
    R = TB[:3, :3]
    d = np.empty(3)
    for i in range(3):
        d[i] = tip[i] - TB[i, 3]
    v = np.empty(3)
    p = np.empty(3)
    _rt3(R, d, p, 0)
    W = np.empty(6)
    _rt3(R, normal, W, 0)
    _cross_into(p, 0, W, 0, W, 3)
    Tf = np.empty(6)
    _rt3(R, omega, Tf, 0)
    _rt3(R, travel, v, 0)
    _cross_into(Tf, 0, p, 0, d, 0)  # ω × p (d reused)
    for i in range(3):
        Tf[3 + i] = v[i] - d[i]  # the tip moves by `travel`, turning about the tip
    Wt = np.zeros(6)
    sliding = friction > 0.0 and use_slip
    if sliding:
        _rt3(R, slip, Wt, 0)
        _cross_into(p, 0, Wt, 0, Wt, 3)
    b = np.empty(6)
    for i in range(6):
        b[i] = W[i] - friction * Wt[i]
    x = np.empty(6)
    if not solve6(K, b, x):
        return False
    Tc = np.empty(6)
    for i in range(6):
        Tc[i] = -dlam * x[i]
    dp = np.empty(3)
    _cross_into(Tc, 0, p, 0, dp, 0)
    for i in range(3):
        dp[i] += Tc[3 + i]
    dpn = dp[0] * W[0] + dp[1] * W[1] + dp[2] * W[2]
    dpl = math.sqrt(dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2])
    scale = max(abs(dpn) / max_correction, dpl / (tangential_factor * max_correction), 1.0)
    c = -(dlam / scale)
    dw = np.empty(6)
    wn2 = 0.0
    tn2 = 0.0
    dn2 = 0.0
    r = 0.0
    cd = 0.0
    for i in range(6):
        dw[i] = c * W[i]
        wn2 += W[i] * W[i]
        tn2 += Tf[i] * Tf[i]
        dn2 += dw[i] * dw[i]
        cd += W[i] * dw[i]
        r += W[i] * Tf[(i + 3) % 6]  # w · (T_f Δ)
    if not (math.isfinite(wn2) and math.isfinite(tn2) and math.isfinite(dn2)):
        return False  # (the NumPy formulation names the vector that is not finite)
    wn = math.sqrt(wn2)
    if wn == 0.0:
        return False
    cd /= wn * wn
    res = 0.0
    for i in range(6):
        res += (dw[i] - W[i] * cd) ** 2
    tiny = 2.2250738585072014e-308
    if math.sqrt(res) > in_tol * max(math.sqrt(dn2), tiny):
        return False
    if abs(r) > in_tol * max(wn * math.sqrt(tn2), tiny):
        return False
    if not solve6(K, dw, x):
        return False
    for i in range(6):
        out[i] = Tf[i] + x[i]  # = T_f + T_c
    if sliding:
        if not solve6(K, Wt, x):
            return False
        for i in range(6):
            out[i] = out[i] + (dlam / scale) * friction * x[i]
    if use_hold:  # the sliding contact's force turns with the surface, not the base
        ws = np.empty(3)
        f = np.empty(3)
        _rt3(R, hold_w, ws, 0)
        _rt3(R, hold_f, f, 0)
        for i in range(3):
            ws[i] -= Tf[i]
        h = np.empty(6)
        _cross_into(ws, 0, f, 0, h, 0)
        _cross_into(p, 0, h, 0, h, 3)
        if not solve6(K, h, x):
            return False
        for i in range(6):
            out[i] = out[i] - x[i]
    return True
