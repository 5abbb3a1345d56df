"""Standard DH table from joint axes: the lecture notes' frame-assignment algorithm.

Given the joint axes of a serial chain as lines (in one configuration, in the base/world frame),
assign the DH frames and read off the table (lecture notes, "Algorithm for using DH for forward
kinematics", steps 1 and 2):

1. (a) ``z_{i-1}`` along the axis of joint ``i``, pointing the way the axis was given (the sense
   of positive joint motion).
   (b) Base frame ``o_0 x_0 y_0 z_0`` (see :func:`default_base`, or the caller's).
   (c) For ``i = 1 … n-1``, ``x_i`` from the relation of ``z_{i-1}`` and ``z_i``:

   - skew: ``x_i`` along the common normal, from ``z_{i-1}`` towards ``z_i``; ``o_i`` where it
     meets ``z_i``;
   - parallel: the perpendicular through ``o_{i-1}`` (so ``d_i = 0``), towards ``z_i``; ``α_i`` is
     0, or π when the two axes point opposite ways;
   - intersecting: ``x_i = z_{i-1} × z_i`` normalised (the choice that makes ``0 < α_i < π``),
     ``o_i`` at the intersection, ``a_i = 0``;
   - coincident (the same line): ``x_i = x_{i-1}``, ``o_i = o_{i-1}``, so ``θ_i = d_i = a_i = 0``
     and ``α_i`` is 0 or π.

   (d) End-effector frame: ``z_n`` along ``z_{n-1}``. Without a tool, frame n is frame n-1 moved
   by joint n (the row is all zeros). With a tool pose, ``o_n`` is the tool point and ``x_n`` the
   perpendicular from ``z_{n-1}`` to it ("parallel"), or, when the tool point lies on ``z_{n-1}``
   ("coincident"), the tool's x axis projected normal to ``z_{n-1}`` (its y axis if x is along
   ``z_{n-1}``); what remains of the tool pose is the model's constant tool transform.

2. The table: ``H_i^{i-1} = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)``, rows ``(θ_i, d_i, a_i, α_i)``.
   The θ_i (and d_i of prismatic joints) are the joint offsets of the configuration in which the
   axes were given, so the chain built from the table places every joint axis on its given line,
   with its given direction, at q = 0.

Each row is computed from the previous frame *as the table rebuilds it*, so every frame is an
exact product of DH links and rounding does not accumulate along the chain.

Tolerances: directions with ``|z_{i-1} × z_i| ≤ tol`` are parallel; lines closer than
``tol · L`` meet, with ``L = max(1, largest coordinate norm of the foot points, the tool and base
origins)`` (lengths are in the model's own unit).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel, from_standard_dh
from kinestat.spatial.plucker import COINCIDENT, INTERSECTING, LINE_KINDS, PARALLEL, SKEW
from kinestat.spatial.transforms import inv, rot_x, rot_z, trans_x, trans_z
from kinestat.spatial.validate import as_pose, freeze_fields

__all__ = [
    "RELATIONS",
    "SKEW",
    "PARALLEL",
    "INTERSECTING",
    "COINCIDENT",
    "DHFromAxes",
    "axis_lines",
    "dh_link",
    "dh_row_from_frames",
    "dh_step",
    "end_step",
    "default_base",
    "assign_dh_frames",
    "dh_from_axes",
]

#: Relation of neighbouring z axes, indexed by the integer codes SKEW, PARALLEL, INTERSECTING,
#: COINCIDENT: the line relations of :mod:`kinestat.spatial.plucker` (one definition).
RELATIONS: tuple[str, ...] = LINE_KINDS

# Below this |x_tool × z| the tool's x axis is taken as along z and its y axis used instead.
_TOOL_X_ALONG_Z = 1e-6


def _dot(a, b) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def _unit(v, n) -> np.ndarray:
    return v / np.where(n > 0, n, 1.0)[..., None]


def _axes_array(axes) -> np.ndarray:
    try:
        return np.asarray(axes, dtype=float)
    except (TypeError, ValueError) as exc:  # strings, ragged lists
        raise InputError(f"joint axes must be an array of numbers ({exc})") from exc


def _where_first(mask: np.ndarray) -> str:
    idx = np.argwhere(mask)[0]
    return ", ".join(str(int(i)) for i in idx)


def axis_lines(axes) -> tuple[np.ndarray, np.ndarray]:
    """Joint axes as (feet, unit directions), each ``(..., n, 3)``.

    ``axes`` is ``(..., n, 2, 3)`` (a point on each axis and its direction, any nonzero length)
    or ``(..., n, 6)`` (Plücker ``[S; S0]``, ``S0 = r × S``, any nonzero scale; Vibhute
    eq. A-7). The returned point is the foot of the perpendicular from the origin, so the result
    depends only on the lines, not on the points chosen on them.
    """
    A = _axes_array(axes)
    if A.ndim >= 3 and A.shape[-2:] == (2, 3):
        point, S = A[..., 0, :], A[..., 1, :]
        what = "direction"
    elif A.ndim >= 2 and A.shape[-1] == 6:
        S, S0 = A[..., :3], A[..., 3:]
        point = None
        what = "Plücker direction S"
    else:
        raise InputError(
            f"joint axes must have shape (n, 2, 3) (point, direction) or (n, 6) (Plücker), "
            f"got {A.shape}"
        )
    per_axis = A.shape[: A.ndim - (2 if point is not None else 1)]
    if per_axis[-1] == 0:
        raise InputError("no joint axes given: a chain needs at least one axis")
    if not np.all(np.isfinite(A)):
        bad = ~np.all(np.isfinite(A.reshape(per_axis + (-1,))), axis=-1)
        raise InputError(f"joint axis [{_where_first(bad)}] contains NaN or infinity")
    n = np.linalg.norm(S, axis=-1)
    zero = n <= np.finfo(float).tiny
    if np.any(zero):
        raise InputError(
            f"joint axis [{_where_first(zero)}] has a zero {what}: give a nonzero direction"
        )
    u = S / n[..., None]
    if point is None:
        off = np.abs(_dot(S, S0)) > 1e-6 * n * np.maximum(np.linalg.norm(S0, axis=-1), n)
        if np.any(off):
            raise InputError(
                f"joint axis [{_where_first(off)}] is not a line: Plücker coordinates [S; S0] "
                "need S . S0 = 0 (S0 = r x S for a point r on the line)"
            )
        point = np.cross(S, S0) / (n**2)[..., None]
    foot = point - _dot(point, u)[..., None] * u
    return foot, u


def dh_link(row) -> np.ndarray:
    """``H_i^{i-1} = Rz(θ) Tz(d) Tx(a) Rx(α)`` for rows ``(..., 4)`` = (θ, d, a, α) (lecture
    notes, step 3)."""
    row = np.asarray(row, dtype=float)
    th, d, a, al = (row[..., k] for k in range(4))
    return rot_z(th) @ trans_z(d) @ trans_x(a) @ rot_x(al)


def dh_row_from_frames(F_prev, F) -> np.ndarray:
    """DH row (θ, d, a, α) relating two DH frames (world poses ``(..., 4, 4)``).

    The lecture notes' definitions: θ the angle from x_{i-1} to x_i about z_{i-1}, d the
    distance from x_{i-1} to x_i along z_{i-1}, a the distance from z_{i-1} to z_i along x_i, α
    the angle from z_{i-1} to z_i about x_i. Exact when ``F = F_prev · H(θ, d, a, α)``.
    """
    F_prev = np.asarray(F_prev, dtype=float)
    F = np.asarray(F, dtype=float)
    x0, y0, z0, o0 = (F_prev[..., :3, k] for k in range(4))
    x, z, o = F[..., :3, 0], F[..., :3, 2], F[..., :3, 3]
    r = o - o0
    theta = np.arctan2(_dot(x, y0), _dot(x, x0))
    alpha = np.arctan2(_dot(np.cross(z0, z), x), _dot(z0, z))
    return np.stack([theta, _dot(r, z0), _dot(r, x), alpha], axis=-1)


def dh_step(F_prev, point, u, tol: float, tol_dist) -> tuple[np.ndarray, np.ndarray]:
    """Lecture notes step 1(c) for one link: the row (θ_i, d_i, a_i, α_i) placing z_i on the
    line (``point``, unit ``u``), and the relation code of z_{i-1} and z_i. Batched.

    ``F_prev`` is frame i-1 (its z is z_{i-1}); ``tol`` bounds ``|z_{i-1} × u|`` for parallel
    axes and ``tol_dist`` the distance at which lines meet.
    """
    F_prev = np.asarray(F_prev, dtype=float)
    x0, y0, z, o = (F_prev[..., :3, k] for k in range(4))
    r = np.asarray(point, dtype=float) - o
    u = np.asarray(u, dtype=float)
    w = np.cross(z, u)
    s = np.linalg.norm(w, axis=-1)
    c = _dot(z, u)
    par = s <= tol
    s_safe = np.where(par, 1.0, s)
    nhat = w / s_safe[..., None]
    t1 = _dot(np.cross(r, u), w) / s_safe**2  # foot of the common normal on z_{i-1}: o + t1 z
    delta = _dot(r, nhat)  # signed length of the common normal along z_{i-1} × z_i
    r_perp = r - _dot(r, z)[..., None] * z  # parallel: perpendicular from o_{i-1} to the line
    dist = np.linalg.norm(r_perp, axis=-1)
    tol_dist = np.asarray(tol_dist, dtype=float)
    skew = ~par & (np.abs(delta) > tol_dist)
    coin = par & (dist <= tol_dist)
    x = np.where(
        par[..., None],
        np.where(coin[..., None], x0, _unit(r_perp, dist)),
        np.where((skew & (delta < 0))[..., None], -nhat, nhat),
    )
    theta = np.where(coin, 0.0, np.arctan2(_dot(x, y0), _dot(x, x0)))
    d = np.where(par, 0.0, t1)
    a = np.where(skew, np.abs(delta), np.where(par & ~coin, dist, 0.0))
    alpha = np.where(par, np.where(c > 0, 0.0, np.pi), np.arctan2(_dot(w, x), c))
    rel = np.where(par, np.where(coin, COINCIDENT, PARALLEL), np.where(skew, SKEW, INTERSECTING))
    return np.stack(np.broadcast_arrays(theta, d, a, alpha), axis=-1), rel


def end_step(F_prev, tool, tol_dist) -> tuple[np.ndarray, np.ndarray]:
    """Lecture notes step 1(d): the row placing the end-effector frame n at the tool point, z_n
    along z_{n-1}; and the relation of z_{n-1} to the tool line (parallel or coincident).

    ``tool`` is the tool pose in the world frame ``(..., 4, 4)``. ``x_n`` is the perpendicular from
    z_{n-1} to the tool point, or, if the point lies on z_{n-1}, the tool's x axis projected
    normal to z_{n-1} (its y axis if x is along z_{n-1}).
    """
    F_prev = np.asarray(F_prev, dtype=float)
    tool = np.asarray(tool, dtype=float)
    x0, y0, z, o = (F_prev[..., :3, k] for k in range(4))
    r = tool[..., :3, 3] - o
    h = _dot(r, z)
    r_perp = r - h[..., None] * z
    dist = np.linalg.norm(r_perp, axis=-1)
    coin = dist <= np.asarray(tol_dist, dtype=float)
    px = tool[..., :3, 0] - _dot(tool[..., :3, 0], z)[..., None] * z
    py = tool[..., :3, 1] - _dot(tool[..., :3, 1], z)[..., None] * z
    nx = np.linalg.norm(px, axis=-1)
    use_y = nx <= _TOOL_X_ALONG_Z
    xc = np.where(use_y[..., None], _unit(py, np.linalg.norm(py, axis=-1)), _unit(px, nx))
    x = np.where(coin[..., None], xc, _unit(r_perp, dist))
    theta = np.arctan2(_dot(x, y0), _dot(x, x0))
    a = np.where(coin, 0.0, dist)
    row = np.stack(np.broadcast_arrays(theta, h, a, np.zeros_like(theta)), axis=-1)
    return row, np.where(coin, COINCIDENT, PARALLEL)


def _provisional_base(foot, u) -> np.ndarray:
    """z along ``u``, origin ``foot``, x the world x axis projected normal to z (world y if z is
    along world x)."""
    ex = np.array([1.0, 0.0, 0.0])
    ey = np.array([0.0, 1.0, 0.0])
    px = ex - u[..., :1] * u
    py = ey - u[..., 1:2] * u
    nx = np.linalg.norm(px, axis=-1)
    x = np.where((nx > 1e-3)[..., None], _unit(px, nx), _unit(py, np.linalg.norm(py, axis=-1)))
    P = np.zeros(u.shape[:-1] + (4, 4))
    P[..., :3, 0] = x
    P[..., :3, 1] = np.cross(u, x)
    P[..., :3, 2] = u
    P[..., :3, 3] = foot
    P[..., 3, 3] = 1.0
    return P


def default_base(feet, u, *, tool=None, tol: float = 1e-9, tol_dist=1e-9) -> np.ndarray:
    """The base frame chosen when none is given (lecture notes step 1(b): x_0 is arbitrary).

    z_0 along axis 1. Start from the frame with origin at the foot of the perpendicular from the
    world origin to axis 1 and x along the world x axis projected normal to z_0 (world y if z_0
    is within about 0.06° of world x). Then turn x_0 onto x_1 (so θ_1 = 0) and, when axes 1 and 2
    are skew or intersect, slide o_0 to the foot of their common normal (so d_1 = 0). With one
    joint, x_0 is turned onto the end-effector frame's x_1 instead (no slide). When axes 1 and 2
    coincide the starting frame is kept.
    """
    feet = np.asarray(feet, dtype=float)
    u = np.asarray(u, dtype=float)
    P = _provisional_base(feet[..., 0, :], u[..., 0, :])
    if u.shape[-2] >= 2:
        row, rel = dh_step(P, feet[..., 1, :], u[..., 1, :], tol, tol_dist)
        slide = np.where((rel == SKEW) | (rel == INTERSECTING), row[..., 1], 0.0)
    elif tool is not None:
        row, _ = end_step(P, tool, tol_dist)
        slide = np.zeros(row.shape[:-1])
    else:
        return P
    return P @ rot_z(row[..., 0]) @ trans_z(slide)


def assign_dh_frames(
    axes, *, base=None, tool=None, tol: float = 1e-9
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The lecture notes' DH frame assignment for joint axes ``(..., n, 2, 3)`` or ``(..., n, 6)``.

    Args:
        axes: the joint axes as lines (see :func:`axis_lines`), in the world frame, in one
            configuration of the chain; each direction is the positive sense of its joint.
        base: frame 0 as a world pose ``(..., 4, 4)``: its z axis must lie on axis 1 and point
            along it. ``None``: :func:`default_base`.
        tool: the end-effector (tool) pose in the world frame, ``(..., 4, 4)``, for step 1(d).
        tol: parallel-direction tolerance (``|z_{i-1} × z_i|``); distances below ``tol · L``
            count as zero (``L`` see the module docstring).

    Returns:
        ``(table, frames, relations, tool_residual)``: rows ``(..., n, 4)`` = (θ, d, a, α) in
        radians; DH frames 0..n ``(..., n+1, 4, 4)``; relation codes ``(..., n)`` (row i: z_{i-1}
        to z_i; row n: z_{n-1} to the tool line, coincident when there is no tool); the constant
        transform from frame n to the tool pose ``(..., 4, 4)`` (identity without a tool).
    """
    feet, u = axis_lines(axes)
    if not (np.isfinite(tol) and tol >= 0):
        raise InputError(f"tol must be a finite non-negative number, got {tol!r}")
    n = u.shape[-2]
    lead = u.shape[:-2]
    scale = np.max(np.linalg.norm(feet, axis=-1), axis=-1)
    if tool is not None:
        tool = as_pose(tool, "tool", last_row_tol=0.0)
        lead = np.broadcast_shapes(lead, tool.shape[:-2])
        scale = np.maximum(scale, np.linalg.norm(tool[..., :3, 3], axis=-1))
    if base is not None:
        base = as_pose(base, "base", last_row_tol=0.0)
        lead = np.broadcast_shapes(lead, base.shape[:-2])
        scale = np.maximum(scale, np.linalg.norm(base[..., :3, 3], axis=-1))
    tol_dist = tol * np.maximum(scale, 1.0)
    feet = np.broadcast_to(feet, lead + (n, 3))
    u = np.broadcast_to(u, lead + (n, 3))
    if base is None:
        F = default_base(feet, u, tool=tool, tol=tol, tol_dist=tol_dist)
    else:
        F = np.broadcast_to(base, lead + (4, 4))
        z0, o0 = F[..., :3, 2], F[..., :3, 3]
        r = o0 - feet[..., 0, :]
        off = np.linalg.norm(r - _dot(r, u[..., 0, :])[..., None] * u[..., 0, :], axis=-1)
        bad_dir = (np.linalg.norm(np.cross(z0, u[..., 0, :]), axis=-1) > tol) | (
            _dot(z0, u[..., 0, :]) <= 0)
        if np.any(bad_dir):
            raise InputError(
                "base: its z axis must point along joint axis 1 (same direction, within "
                f"tol={tol:g}); turn the base or reverse axis 1's direction"
            )
        if np.any(off > tol_dist):
            raise InputError(
                f"base: its origin is {np.max(off):.3g} from joint axis 1 (allowed "
                f"{np.max(tol_dist):.3g}); frame 0's origin must lie on axis 1 (or pass a larger "
                "tol if the base was given to fewer digits)"
            )
    frames = [F]
    rows = []
    rels = []
    for i in range(1, n):
        row, rel = dh_step(F, feet[..., i, :], u[..., i, :], tol, tol_dist)
        F = F @ dh_link(row)
        frames.append(F)
        rows.append(row)
        rels.append(rel)
    if tool is None:
        row = np.zeros(lead + (4,))
        rel = np.full(lead, COINCIDENT)
    else:
        row, rel = end_step(F, tool, tol_dist)
    F = F @ dh_link(row)
    frames.append(F)
    rows.append(row)
    rels.append(rel)
    residual = np.broadcast_to(np.eye(4), lead + (4, 4)).copy() if tool is None else inv(F) @ tool
    return (np.stack(rows, axis=-2), np.stack(frames, axis=-3),
            np.stack(np.broadcast_arrays(*rels), axis=-1).astype(np.int64), residual)



@dataclass(frozen=True, eq=False)
class DHFromAxes:
    """Result of :func:`dh_from_axes`.

    Attributes:
        table: ``(n, 4)`` standard-DH rows (θ, d, a, α), radians; θ (d for prismatic joints) are
            the joint offsets of the configuration in which the axes were given.
        frames: the DH frames 0..n as world poses ``(n+1, 4, 4)`` at that configuration.
        base: frame 0 (the model's base transform).
        tool: the constant transform from frame n to the given tool pose (identity if none).
        relations: for each row i, how z_{i-1} relates to z_i (``"skew"``, ``"parallel"``,
            ``"intersecting"``, ``"coincident"``); the last one relates z_{n-1} to the tool line.
        model: the chain ``from_standard_dh(table, kinds, base=base, tool=tool)``.
    """

    table: np.ndarray
    frames: np.ndarray
    base: np.ndarray
    tool: np.ndarray
    relations: tuple[str, ...]
    model: ChainModel

    def __post_init__(self) -> None:
        freeze_fields(self, ("table", "frames", "base", "tool"))
        object.__setattr__(self, "relations", tuple(self.relations))

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.table.shape[0]


def dh_from_axes(
    axes,
    kinds: Sequence[str] | None = None,
    *,
    base=None,
    tool=None,
    tol: float = 1e-9,
    pitches=None,
    limits=None,
    names=None,
    name: str = "dh_from_axes",
    length_unit: str = "mm",
    description: str = "",
) -> DHFromAxes:
    """Standard DH table, frames and chain model from the joint axes of one chain.

    ``axes`` is ``(n, 2, 3)`` (a point on each axis and its direction) or ``(n, 6)`` (Plücker),
    n ≥ 1; ``kinds`` the joint kinds (default all revolute; ``pitches`` for screw joints);
    ``base``, ``tool`` and ``tol`` as in :func:`assign_dh_frames`. The returned model's forward
    kinematics at q = 0 puts joint i's axis on the i-th given line with the given direction, and
    its end pose on ``tool`` (lecture notes, steps 1 and 2). For a batch of axis sets use
    :func:`assign_dh_frames`.

    A vertical waist axis, then two parallel horizontal axes 400 mm apart:

    >>> res = dh_from_axes([[[0, 0, 0], [0, 0, 1]], [[0, 0, 300], [0, -1, 0]],
    ...                     [[0, 0, 700], [0, -1, 0]]])
    >>> res.n, res.relations[:2], round(float(res.table[1, 2]), 6)
    (3, ('intersecting', 'parallel'), 400.0)
    """
    A = _axes_array(axes)
    if not ((A.ndim == 3 and A.shape[1:] == (2, 3)) or (A.ndim == 2 and A.shape[1] == 6)):
        raise InputError(
            f"dh_from_axes takes one chain: axes of shape (n, 2, 3) or (n, 6), got {A.shape} "
            "(use assign_dh_frames for a batch)"
        )
    if tool is not None and np.shape(tool) != (4, 4):
        raise InputError(f"tool must be one 4x4 pose, got shape {np.shape(tool)}")
    if base is not None and np.shape(base) != (4, 4):
        raise InputError(f"base must be one 4x4 pose, got shape {np.shape(base)}")
    if kinds is not None:
        pitch_list = [0.0] * len(kinds) if pitches is None else list(pitches)
        for i, (k, h) in enumerate(zip(kinds, pitch_list, strict=False), start=1):
            if k == "screw" and h == 0.0:
                raise InputError(f"joint {i} is a screw joint: give its non-zero pitch "
                                 "(length per radian) in pitches")
    table, frames, rels, residual = assign_dh_frames(A, base=base, tool=tool, tol=tol)
    model = from_standard_dh(
        table, kinds, pitches=pitches, limits=limits, names=names, base=frames[0],
        tool=residual, name=name, length_unit=length_unit, description=description,
    )
    return DHFromAxes(
        table=table, frames=frames, base=frames[0], tool=residual,
        relations=tuple(RELATIONS[int(k)] for k in rels), model=model,
    )
