"""The one internal serial-chain model.

Every serial mechanism, whatever notation it came in, becomes (DESIGN.md)::

    C0 · Z(q1) · C1 · Z(q2) · … · Z(qn) · Cn

where each ``Ci`` is a constant 4x4 transform and ``Z(q)`` the joint's motion along/about its
local z axis (see :mod:`kinestat.mechanism.joints`). The model is immutable; the parameters the
user gave are kept (``notation`` and ``parameters``) so the model can be written back in its own
notation.

Notations (angles in radians here; files and the CLI use degrees):

- ``standard_dh`` (lecture notes, Spong; Nadkarni eq. 2-7): link transform
  ``Rz(θ) · Tz(d) · Tx(a) · Rx(α)``, the joint variable is θ (revolute/screw) or d (prismatic),
  the given θ or d being an offset added to q. Rows are ``(theta, d, a, alpha)``.
- ``modified_dh`` (Craig; Crane & Duffy, Vibhute eq. 2-26): link transform
  ``Rx(α_ij) · Tx(a_ij) · Rz(θ_j) · Tz(S_j)``. Rows are ``(alpha, a, theta, d)``.
- ``nadkarni``: Nadkarni's (r_i, α_i, a_i, θ_i, pitch) of DISP, which is standard DH with
  d = r; the global frame is placed by three points on x*(1) (SET FIVE), the joint values given
  are the initial configuration, and the seventh (imaginary) joint defines the hand frame.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from kinestat.errors import InputError, ModelError
from kinestat.mechanism.joints import Joint, JointKind, kind_from_pitch
from kinestat.spatial.displacement import frame_from_points
from kinestat.spatial.transforms import inv, rot_x, rot_z, trans_x, trans_z
from kinestat.spatial.validate import as_pose, frozen

__all__ = [
    "ChainModel",
    "from_standard_dh",
    "from_modified_dh",
    "from_nadkarni",
    "frame_from_three_points",
    "NOTATIONS",
]

NOTATIONS = ("chain", "standard_dh", "modified_dh", "nadkarni")



def _check_pose(T, name: str) -> np.ndarray:
    """A model's constant pose (base, tool, Ci): a rigid ``(4, 4)`` with an exact last row."""
    return as_pose(T, name, single=True, error=ModelError)


@dataclass(frozen=True, eq=False)
class ChainModel:
    """An immutable serial chain ``C0 · Z(q1) · C1 · … · Z(qn) · Cn``.

    Attributes:
        name: model name.
        joints: the n joints.
        constants: read-only array ``(n+1, 4, 4)`` of the constant transforms ``C0 … Cn``.
        length_unit: unit of every length in the model (``"mm"``, ``"m"``, ...).
        notation: the notation the user gave (``chain``, ``standard_dh``, ``modified_dh``,
            ``nadkarni``).
        parameters: read-only ``(n, 4)`` rows in that notation (radians), for write-back.
        base, tool: the base and tool transforms the user gave (for write-back).
        q_home: a reference configuration (the initial one for Nadkarni decks).
        extra: notation-specific data kept for write-back (e.g. Nadkarni's frame points and
            seventh joint), as a tuple of ``(key, value)`` pairs.

    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]], name='rr')
    >>> arm, arm.n, arm.constants.shape
    (ChainModel('rr', RR, notation='standard_dh', unit='mm'), 2, (3, 4, 4))
    """

    name: str
    joints: tuple[Joint, ...]
    constants: np.ndarray
    length_unit: str = "mm"
    notation: str = "chain"
    parameters: np.ndarray | None = None
    base: np.ndarray = field(default_factory=lambda: frozen(np.eye(4), float))
    tool: np.ndarray = field(default_factory=lambda: frozen(np.eye(4), float))
    q_home: np.ndarray | None = None
    description: str = ""
    extra: tuple = ()

    def __post_init__(self) -> None:
        joints = tuple(self.joints)
        object.__setattr__(self, "joints", joints)
        C = np.asarray(self.constants, dtype=float)
        n = len(joints)
        if n == 0:
            raise ModelError(f"model {self.name!r} has no joints")
        if C.shape != (n + 1, 4, 4):
            raise ModelError(
                f"model {self.name!r}: constants must have shape {(n + 1, 4, 4)}, got {C.shape}"
            )
        for i in range(n + 1):
            _check_pose(C[i], f"model {self.name!r} constant transform C{i}")
        object.__setattr__(self, "constants", frozen(C, float))
        if self.notation not in NOTATIONS:
            raise ModelError(f"unknown notation {self.notation!r}; expected one of {NOTATIONS}")
        if self.parameters is not None:
            P = np.asarray(self.parameters, dtype=float)
            if P.shape != (n, 4):
                raise ModelError(f"model {self.name!r}: parameters must be (n, 4) rows")
            object.__setattr__(self, "parameters", frozen(P, float))
        object.__setattr__(self, "base", frozen(_check_pose(self.base, "base"), float))
        object.__setattr__(self, "tool", frozen(_check_pose(self.tool, "tool"), float))
        qh = np.zeros(n) if self.q_home is None else np.asarray(self.q_home, dtype=float)
        if qh.shape != (n,) or not np.all(np.isfinite(qh)):
            raise ModelError(f"model {self.name!r}: q_home must be {n} finite values")
        object.__setattr__(self, "q_home", frozen(qh, float))
        kinds = frozen(np.array([int(j.code) for j in joints], dtype=np.int64), float)
        pitches = frozen(np.array([j.pitch if j.kind == "screw" else 0.0 for j in joints]), float)
        object.__setattr__(self, "_kinds", kinds)
        object.__setattr__(self, "_pitches", pitches)
        # the compiled kernels' per-model data lives outside the model, in
        # kinestat.serial._kernel_cache (Pinocchio's Model/Data split)

    # -- derived, cheap views ------------------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def kind_codes(self) -> np.ndarray:
        """Joint kinds as :class:`~kinestat.mechanism.joints.JointKind` codes (int64, read-only)."""
        return self._kinds  # type: ignore[attr-defined]

    @property
    def prismatic(self) -> np.ndarray:
        """Boolean mask of prismatic joints."""
        return self.kind_codes == JointKind.PRISMATIC

    @property
    def pitches(self) -> np.ndarray:
        """Pitch of each joint (0 for revolute and prismatic), read-only."""
        return self._pitches  # type: ignore[attr-defined]

    @property
    def lower(self) -> np.ndarray:
        """Lower joint limits ``(n,)``."""
        return np.array([j.lower for j in self.joints])

    @property
    def upper(self) -> np.ndarray:
        """Upper joint limits ``(n,)``."""
        return np.array([j.upper for j in self.joints])

    def extra_dict(self) -> dict:
        """The notation-specific extras as a dict."""
        return dict(self.extra)

    def check_q(self, q, name: str = "q") -> np.ndarray:
        """Validate joint values ``(..., n)``; returns a float array."""
        try:
            q = np.asarray(q, dtype=float)
        except (TypeError, ValueError) as exc:  # strings, ragged lists, None in a list...
            raise InputError(f"{name} must be numbers of shape (..., {self.n}) for model "
                             f"{self.name!r}: {exc}") from exc
        if q.ndim == 0 or q.shape[-1] != self.n:
            raise InputError(
                f"{name} must have shape (..., {self.n}) for model {self.name!r}, got {q.shape}"
            )
        if not np.all(np.isfinite(q)):
            raise InputError(f"{name} contains NaN or infinity")
        return q

    def within_limits(self, q, tol: float = 0.0) -> np.ndarray:
        """True where every joint value lies within its limits (``tol`` slack)."""
        q = self.check_q(q)
        return np.all((q >= self.lower - tol) & (q <= self.upper + tol), axis=-1)

    def __repr__(self) -> str:
        kinds = "".join({"revolute": "R", "prismatic": "P", "screw": "H"}[j.kind]
                        for j in self.joints)
        return (f"ChainModel({self.name!r}, {kinds}, notation={self.notation!r}, "
                f"unit={self.length_unit!r})")


def _joints(kinds: Sequence[str] | None, n: int, pitches, limits, names) -> tuple[Joint, ...]:
    kinds = ["revolute"] * n if kinds is None else list(kinds)
    if len(kinds) != n:
        raise ModelError(f"{len(kinds)} joint kinds given for {n} rows")
    pitches = [0.0] * n if pitches is None else list(pitches)
    limits = [(-math.inf, math.inf)] * n if limits is None else list(limits)
    names = [str(i + 1) for i in range(n)] if names is None else list(names)
    if not (len(pitches) == len(limits) == len(names) == n):
        raise ModelError("pitches, limits and names must have one entry per joint")
    return tuple(
        Joint(kind=k, pitch=float(p), lower=float(lo), upper=float(hi), name=str(nm))
        for k, p, (lo, hi), nm in zip(kinds, pitches, limits, names, strict=True)
    )


def _numbers(x, what: str) -> np.ndarray:
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:  # strings, ragged rows
        raise ModelError(f"{what}: expected an array of numbers ({exc})") from exc


def _rows(rows, name: str) -> np.ndarray:
    P = _numbers(rows, name)
    if P.ndim != 2 or P.shape[1] != 4 or P.shape[0] == 0:
        raise ModelError(f"{name}: expected rows of 4 parameters, got shape {P.shape}")
    if not np.all(np.isfinite(P)):
        raise ModelError(f"{name}: parameters contain NaN or infinity")
    return P


def _prepare(rows, label, kinds, pitches, limits, names, base, tool):
    """The checked table, joints, base and tool shared by the DH constructors."""
    P = _rows(rows, label)
    joints = _joints(kinds, P.shape[0], pitches, limits, names)
    base = np.eye(4) if base is None else _check_pose(base, "base")
    tool = np.eye(4) if tool is None else _check_pose(tool, "tool")
    return P, joints, base, tool


def from_standard_dh(
    rows,
    kinds: Sequence[str] | None = None,
    *,
    pitches=None,
    limits=None,
    names=None,
    base=None,
    tool=None,
    name: str = "chain",
    length_unit: str = "mm",
    q_home=None,
    description: str = "",
) -> ChainModel:
    """Chain from standard DH rows ``(theta, d, a, alpha)`` (radians).

    Link i is ``Rz(θi + qi) · Tz(di) · Tx(ai) · Rx(αi)`` for a revolute joint, ``Rz(θi) ·
    Tz(di + qi) · …`` for a prismatic one and ``Rz(θi + qi) · Tz(di + h qi) · …`` for a screw
    (lecture notes' H_i^{i-1}; Nadkarni eq. 2-7). Rz and Tz commute, so each link is
    ``Z(qi) · Ci`` with ``Ci = Rz(θi) Tz(di) Tx(ai) Rx(αi)``.

    >>> arm = from_standard_dh([[0.0, 0.5, 1.0, np.pi / 2]], ['prismatic'])
    >>> arm.joints[0].kind, arm.constants[1][:3, 3]
    ('prismatic', array([1. , 0. , 0.5]))
    """
    P, joints, base, tool = _prepare(rows, "standard DH table", kinds, pitches, limits, names,
                                     base, tool)
    n = P.shape[0]
    th, d, a, al = P.T
    links = rot_z(th) @ trans_z(d) @ trans_x(a) @ rot_x(al)
    C = np.empty((n + 1, 4, 4))
    C[0] = base
    C[1:] = links
    C[n] = links[n - 1] @ tool
    return ChainModel(
        name=name, joints=joints, constants=C, length_unit=length_unit, notation="standard_dh",
        parameters=P, base=base, tool=tool, q_home=q_home, description=description,
    )


def from_modified_dh(
    rows,
    kinds: Sequence[str] | None = None,
    *,
    pitches=None,
    limits=None,
    names=None,
    base=None,
    tool=None,
    name: str = "chain",
    length_unit: str = "mm",
    q_home=None,
    description: str = "",
) -> ChainModel:
    """Chain from modified DH rows ``(alpha, a, theta, d)`` (radians).

    Link j is ``Rx(α_ij) · Tx(a_ij) · Rz(θj + qj) · Tz(Sj)`` (Craig; Crane & Duffy, Vibhute
    eq. 2-26), i.e. ``Pj · Z(qj)`` with ``Pj = Rx(α) Tx(a) Rz(θ) Tz(d)``.

    >>> arm = from_modified_dh([[0.0, 1.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
    >>> arm.constants[0][:3, 3], arm.constants[1][:3, 3]
    (array([1., 0., 0.]), array([1., 0., 0.]))
    """
    P, joints, base, tool = _prepare(rows, "modified DH table", kinds, pitches, limits, names,
                                     base, tool)
    n = P.shape[0]
    al, a, th, d = P.T
    pre = rot_x(al) @ trans_x(a) @ rot_z(th) @ trans_z(d)
    C = np.empty((n + 1, 4, 4))
    C[0] = base @ pre[0]
    C[1:n] = pre[1:]
    C[n] = tool
    return ChainModel(
        name=name, joints=joints, constants=C, length_unit=length_unit, notation="modified_dh",
        parameters=P, base=base, tool=tool, q_home=q_home, description=description,
    )


def frame_from_three_points(p1, p2, p3, *, what: str = "frame points") -> np.ndarray:
    """Pose with origin p1, z towards p2 and p3 in the z-x half plane (Nadkarni eqs. 3-1..3-3).

    :func:`kinestat.spatial.displacement.frame_from_points`, with ``what`` naming the points in
    error messages (e.g. "SET FIVE frame points").

    >>> frame_from_three_points([1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [2.0, 0.0, 0.0])[:3, 3]
    array([1., 0., 0.])
    """
    try:
        return frame_from_points(p1, p2, p3)
    except InputError as exc:
        raise InputError(f"{what}: {exc}") from exc


def from_nadkarni(
    joints_rows,
    frame_points,
    *,
    n_active: int | None = 6,
    limits=None,
    name: str = "nadkarni",
    length_unit: str = "in",
    description: str = "",
) -> ChainModel:
    """Chain from Nadkarni's notation (DISP SET FOUR and SET FIVE).

    Args:
        joints_rows: ``(N, 5)`` rows ``(r, alpha, a, theta, pitch)`` with angles in radians and
            pitch in length per radian (> 1e5 means prismatic, 0 revolute). The values are the
            initial configuration.
        frame_points: three points on x*(1) in its initial position (origin, a point on +z,
            a point on +x), SET FIVE.
        n_active: how many joints move (DISP: the first six). The next joint, when present, is
            the imaginary hand joint: the hand frame is x*(n_active+1) (its z along that axis,
            its x along that joint's normal). ``None`` makes every joint active (DISP MS = 2).

    Nadkarni's transformation x(i-1) ← x(i) is ``Rz(θi) Tz(ri) Tx(ai) Rx(αi)`` (eqs. 2-5, 2-7),
    standard DH with d = r, and x*(i) = x(i-1) · Rz(θi) Tz(ri). The base x(0) follows from the
    initial x*(1) = x*(0) given by the three points (eqs. 2-13 to 2-15).

    >>> rows = [[0.0, 0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0]]
    >>> m = from_nadkarni(rows, [[0, 0, 0], [0, 0, 1], [1, 0, 0]], n_active=None)
    >>> m.notation, m.n, m.q_home
    ('nadkarni', 2, array([0., 0.]))
    """
    R = _numbers(joints_rows, "Nadkarni joint rows")
    if R.ndim != 2 or R.shape[1] != 5 or R.shape[0] == 0:
        raise ModelError(
            f"Nadkarni joints must be rows of (r, alpha, a, theta, pitch), got {R.shape}")
    if not np.all(np.isfinite(R)):
        raise ModelError("Nadkarni joint parameters contain NaN or infinity")
    N = R.shape[0]
    n = N if n_active is None else n_active
    if n < 1 or n > N:
        raise ModelError(f"n_active={n_active} but the mechanism has {N} joints")
    r, alpha, a, theta, pitch = R.T
    kinds = [kind_from_pitch(float(p)) for p in pitch[:n]]
    pitches = [p if k == "screw" else 0.0 for p, k in zip(pitch[:n], kinds, strict=True)]
    q0 = np.array([r[i] if kinds[i] == "prismatic" else theta[i] for i in range(n)])
    # Standard DH rows with the variable part zeroed: offsets such that q = the absolute value.
    th_off = np.where(np.array(kinds) == "prismatic", theta[:n], 0.0)
    d_off = np.where(np.array(kinds) == "prismatic", 0.0, r[:n])
    # a screw joint's r changes by h·(θ − θ0): r = r0 + h (q − θ0) → constant part r0 − h θ0
    d_off = d_off - np.where(np.array(kinds) == "screw", np.array(pitches) * theta[:n], 0.0)
    rows = np.stack([th_off, d_off, a[:n], alpha[:n]], axis=1)
    fp = np.asarray(frame_points, dtype=float)
    if fp.shape != (3, 3):
        raise ModelError(f"frame points (SET FIVE) must be three points, got shape {fp.shape}")
    xstar1 = frame_from_three_points(fp[0], fp[1], fp[2], what="SET FIVE frame points")
    # x*(1) = x(0) · Rz(θ1) Tz(r1)  →  x(0) = x*(1) · (Rz(θ1) Tz(r1))^-1
    base = xstar1 @ inv(rot_z(theta[0]) @ trans_z(r[0]))
    if n < N:
        hand = rot_z(theta[n]) @ trans_z(r[n])
    else:
        hand = np.eye(4)
    model = from_standard_dh(
        rows, kinds, pitches=pitches, limits=limits, base=base, tool=hand, name=name,
        length_unit=length_unit, q_home=q0, description=description,
    )
    extra = (("frame_points", frozen(fp, float)), ("rows", frozen(R, float)), ("n_active", n))
    object.__setattr__(model, "notation", "nadkarni")
    object.__setattr__(model, "extra", extra)
    return model
