"""Composition root of ``kinestat control --arm MODEL``: any 6-joint arm with an analytic solver
carrying the compliant platform in the in-process simulated cell.

The thesis's cell is a PUMA 762 behind a Galil controller and an encoder box
(:mod:`kinestat.app.sim_cell`); those protocols are the PUMA's hardware. Another arm runs on
the simulated cell in-process (:class:`~kinestat.app.sim_cell.InProcessIO` with a
:class:`~kinestat.sim.arm.SimulatedArm`): its joints are set directly, in radians, within its
limits; the flange pose is the model's forward kinematics; the platform, tool and workpiece
physics are the thesis cell's. The controller drives it through
:class:`~kinestat.control.arm.ChainArm` (``kinestat.ik_all`` and the shared nearest-solution
selection), with a fine command resolution (:data:`ARM_DEG_PER_COUNT`) and no axis 4 → 5
coupling.

Frames. The cell's fixed frame is the one ``--start``, ``--direction`` and the workpiece are
given in (for the PUMA 762 its base frame). The arm is loaded in millimetres
(:func:`in_millimetres`) and its base frame is the fixed frame translated to ``arm_base``
(axes parallel). Without ``arm_base`` it is placed automatically (:func:`auto_base`): among
reachable tool positions of the arm, the one where the start pose (tool point, tool axis along
the force, a67 as the controller's default) is reached with the best-conditioned Jacobian and
joint-limit margin, with the arm's shoulder on the tool's side of the workpiece (the tool pushes
away from the shoulder) — then rounded to whole millimetres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from kinestat.app.sim_cell import InProcessIO
from kinestat.control.arm import ChainArm, frame_from_tool
from kinestat.control.model import ControlModel
from kinestat.errors import InputError, KinestatError, ModelError
from kinestat.io.urdf import metres_per_unit
from kinestat.mechanism.chain import ChainModel
from kinestat.robots.puma762.axes import round_half_away
from kinestat.serial.fk import fk
from kinestat.serial.jacobian import jacobian
from kinestat.sim.arm import SimulatedArm
from kinestat.sim.contact import Cell
from kinestat.sim.sensor import Sensor

__all__ = ["ARM_DEG_PER_COUNT", "CONTINUOUS_LIMIT_DEG", "ArmSpec", "PlacedArm", "in_millimetres",
           "placed", "shoulder", "auto_base", "place_arm", "chain_arm", "arm_control_model",
           "arm_start_counts", "arm_io"]

ARM_DEG_PER_COUNT = 1e-4
"""Command resolution of a simulated ``--arm`` (degrees per count): 1.7 µrad, ~2 µm at a metre
(the PUMA 762's counts are ~0.02 mm at the tool)."""

CONTINUOUS_LIMIT_DEG = 360.0
"""The range the controller allows a joint without limits (a URDF ``continuous`` joint): ±360°."""

PLACEMENT_SAMPLES = 1024
"""Candidate tool positions :func:`auto_base` tries (forward kinematics of seeded random joint
vectors within the limits)."""

_LIMIT_COMFORT_DEG = 30.0  # a joint this far from both its limits counts as comfortable


@dataclass(frozen=True, eq=False)
class PlacedArm:
    """An arm in the cell: ``arm`` (the controller's :class:`ChainArm` over the placed
    millimetre model), its base position ``base`` (mm, fixed frame), ``placement`` ("auto" or
    "given") and ``q_start`` (6,) the joints (radians) it starts in: the start pose's solution
    it reaches it with."""

    arm: ChainArm
    base: np.ndarray
    placement: str
    q_start: np.ndarray
    source_name: str

    def header(self) -> dict:
        """The log header's and report's ``arm`` entry (with ``constants``, the placed chain's
    ``C0 … C6`` in mm, so that ``kinestat view log`` draws this arm)."""
        m = self.arm.model
        return {"name": self.source_name, "joints": [j.name for j in m.joints],
                "base": self.base.tolist(), "placement": self.placement,
                "limits_deg": np.asarray(self.arm.limits_deg).tolist(),
                "axis_deg_per_count": ARM_DEG_PER_COUNT,
                "start_joints_deg": np.degrees(self.q_start).tolist(),
                # the placed chain itself (mm): a log replays without the model file
                "constants": np.asarray(m.constants).tolist()}


def in_millimetres(model: ChainModel) -> ChainModel:
    """``model`` with every length in millimetres (the cell's unit), as a plain chain
    (translations of ``C0 … C6``, base, tool and prismatic limits scaled).

    >>> import kinestat
    >>> m = in_millimetres(kinestat.load("puma560"))
    >>> m.length_unit, round(float(kinestat.fk(m, np.zeros(6))[0, 3]), 2)
    ('mm', 452.1)
    """
    k = metres_per_unit(model.length_unit, f"length unit of model {model.name!r}") / 1e-3
    if model.length_unit == "mm":
        return model
    C = np.array(model.constants)
    C[:, :3, 3] *= k

    def pose(T):
        T = np.array(T)
        T[:3, 3] *= k
        return T

    joints = tuple(replace(j, lower=j.lower * k, upper=j.upper * k) if j.kind == "prismatic"
                   else replace(j, pitch=j.pitch * k) if j.kind == "screw" else j
                   for j in model.joints)
    qh = np.where(model.prismatic, model.q_home * k, model.q_home)
    return ChainModel(name=model.name, joints=joints, constants=C, length_unit="mm",
                      base=pose(model.base), tool=pose(model.tool), q_home=qh,
                      description=model.description)


def placed(model: ChainModel, base_xyz) -> ChainModel:
    """``model`` with its base frame translated to ``base_xyz`` (axes parallel)."""
    b = np.asarray(base_xyz, dtype=float)
    T = np.eye(4)
    T[:3, 3] = b
    C = np.array(model.constants)
    C[0] = T @ C[0]
    return ChainModel(name=model.name, joints=model.joints, constants=C,
                      length_unit=model.length_unit, base=T @ model.base, tool=model.tool,
                      q_home=model.q_home, description=model.description)


def chain_arm(model: ChainModel, what: str = "--arm") -> ChainArm:
    """The controller's arm over ``model`` (in mm): 6 revolute joints with an analytic solver;
    joints without limits get ±:data:`CONTINUOUS_LIMIT_DEG`. One clear error otherwise."""
    if not isinstance(model, ChainModel):
        raise InputError(f"{what}: expected a serial chain model")
    if model.n != 6:
        raise InputError(f"{what} {model.name!r} has {model.n} joints: the kinestatic cell needs "
                         "a 6-joint arm (its solver turns each target pose into joint values)")
    lim = np.degrees(np.column_stack([model.lower, model.upper]))
    lim = np.clip(lim, -CONTINUOUS_LIMIT_DEG, CONTINUOUS_LIMIT_DEG)
    try:
        return ChainArm(model, limits_deg=lim)
    except ModelError as exc:
        raise InputError(f"{what} {model.name!r} has no analytic inverse-kinematics solver for "
                         f"the controller: {exc}") from exc


def _tool_points(model: ChainModel, q: np.ndarray, tool_point_6) -> tuple[np.ndarray, np.ndarray]:
    T = fk(model, q)
    return T, np.einsum("...ij,j->...i", T[..., :3, :3], np.asarray(tool_point_6, float)) + \
        T[..., :3, 3]


def _scores(arm: ChainArm, q: np.ndarray, tool_point_6, reach: float) -> np.ndarray:
    """Comfort of joint vectors ``q (..., 6)``: the smallest singular value of the Jacobian at
    the tool point (linear rows over ``reach``), times the joint-limit margin (1 beyond
    30° from both limits)."""
    _, p = _tool_points(arm.model, q, tool_point_6)
    J = jacobian(arm.model, q)
    w, v = J[..., :3, :], J[..., 3:, :]
    v_p = v + np.cross(w, p[..., None, :], axisb=-1, axisc=-2, axisa=-2)
    s = np.linalg.svd(np.concatenate([w, v_p / reach], axis=-2), compute_uv=False)[..., -1]
    lim = np.radians(np.asarray(arm.limits_deg))
    margin = np.minimum(q - lim[:, 0], lim[:, 1] - q).min(axis=-1)
    return s * np.clip(margin / math.radians(_LIMIT_COMFORT_DEG), 0.0, 1.0)


def _solutions(arm: ChainArm, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every solution of ``frames (B, 4, 4)`` within the limits: (q (B, K, 6), ok (B, K))."""
    from kinestat.serial.analytic import wrap_to_limits  # lazy: scipy.linalg, as ChainArm

    res = arm.ik_all(frames)
    lim = np.radians(np.asarray(arm.limits_deg))
    q = np.where(res.valid[..., None], res.q, 0.0)
    q, ok = wrap_to_limits(q, q, lim[:, 0], lim[:, 1], ~arm.model.prismatic)
    return q, ok.all(axis=-1) & res.valid


def shoulder(model: ChainModel) -> np.ndarray:
    """The arm's shoulder (3,): the point of joint 2's axis nearest joint 1's axis at q = 0
    (joint 2's frame origin when the axes are parallel), model frame."""
    F1 = np.array(model.constants[0])
    F2 = F1 @ model.constants[1]
    p1, w1, p2, w2 = F1[:3, 3], F1[:3, 2], F2[:3, 3], F2[:3, 2]
    c = float(w1 @ w2)
    if 1.0 - c * c < 1e-12:
        return p2
    d = p2 - p1
    t = (c * float(d @ w1) - float(d @ w2)) / (1.0 - c * c)  # along joint 2's axis
    return p2 + t * w2


def auto_base(arm: ChainArm, start, s6, a67, tool_point_6) -> tuple[np.ndarray, np.ndarray]:
    """Where to put the base of ``arm`` (its model at the origin, mm) so that the start pose
    is reached comfortably: (base (3,) mm, whole millimetres; the joints q (6,) there).

    Candidate tool positions are those of :data:`PLACEMENT_SAMPLES` seeded random joint
    vectors within the limits; at each the start orientation is solved (``ik_all``), and the
    solution with the best :func:`_scores` wins among those whose tool point ``p``, seen from
    the :func:`shoulder`, satisfies ``p · s6 ≥ 0.1 · reach`` — the tool pushes away from the
    shoulder, which stands behind the workpiece's plane (``reach``: the farthest candidate)."""
    rng = np.random.default_rng(0)
    lim = np.radians(np.asarray(arm.limits_deg))
    lo, hi = np.maximum(lim[:, 0], -math.pi), np.minimum(lim[:, 1], math.pi)
    _, pts = _tool_points(arm.model, rng.uniform(lo, hi, (PLACEMENT_SAMPLES, 6)), tool_point_6)
    rel = pts - shoulder(arm.model)
    reach = float(np.max(np.linalg.norm(rel, axis=-1)))
    pts = pts[rel @ s6 >= 0.1 * reach]
    if len(pts) == 0:
        raise InputError(f"--arm {arm.model.name!r}: no placement found for the start pose; "
                         "give --arm-base x,y,z")
    frames = np.stack([frame_from_tool(p, s6, a67, tool_point_6) for p in pts])
    q, ok = _solutions(arm, frames)
    score = np.where(ok, _scores(arm, q, tool_point_6, reach), -np.inf)
    b, k = np.unravel_index(int(np.argmax(score)), score.shape)
    if not np.isfinite(score[b, k]):
        raise InputError(f"--arm {arm.model.name!r}: the start orientation (tool axis along "
                         "--direction) is not reachable within the joint limits anywhere in the "
                         "arm's workspace")
    base = np.round(np.asarray(start, dtype=float) - pts[b])
    return base, q[b, k]


def place_arm(model: ChainModel, start, s6, a67, tool_point_6, base=None,
              source_name: str | None = None) -> PlacedArm:
    """The arm of ``kinestat control --arm``: ``model`` in millimetres, its base at ``base``
    (mm, fixed frame) or placed by :func:`auto_base`, and the joints it starts in (the start
    pose's most comfortable solution within the limits). An unreachable start pose is an
    InputError naming the arm, the start and the base, before anything moves."""
    mm = in_millimetres(model)
    at_origin = chain_arm(mm)
    s6, a67 = np.asarray(s6, float), np.asarray(a67, float)
    start = np.asarray(start, dtype=float)
    placement = "given"
    if base is None:
        base, _ = auto_base(at_origin, start, s6, a67, tool_point_6)
        placement = "auto"
    base = np.asarray(base, dtype=float)
    arm = ChainArm(placed(mm, base), limits_deg=at_origin.limits_deg)
    q, ok = _solutions(arm, frame_from_tool(start, s6, a67, tool_point_6)[None])
    q, ok = q[0], ok[0]
    where = (f"the start tool point ({', '.join(f'{v:g}' for v in start)}) mm with the tool "
             f"axis along --direction, for --arm {model.name!r} with its base at "
             f"({', '.join(f'{v:g}' for v in base)}) mm")
    if not np.any(ok):
        hint = ("move --arm-base or --start, or omit --arm-base to place the arm automatically"
                if placement == "given" else "give --arm-base x,y,z")
        raise InputError(f"{where} is out of reach within the joint limits; {hint}")
    reach = float(np.linalg.norm(start - base)) or 1.0
    score = np.where(ok, _scores(arm, q, tool_point_6, reach), -np.inf)
    q0 = q[int(np.argmax(score))]
    try:  # the controller's own selection reaches the same start (a consistency check)
        arm.solve_axis(start, s6, a67, tool_point_6, q0, arm.limits_deg)
    except KinestatError as exc:  # pragma: no cover - the solutions above are within limits
        raise InputError(f"{where}: {exc}") from exc
    return PlacedArm(arm=arm, base=base, placement=placement, q_start=q0,
                     source_name=source_name or model.name)


@dataclass(frozen=True, eq=False)
class ArmSpec:
    """The ``--arm`` of a run: the loaded ``model`` (any length unit), its base position
    ``base`` (mm, fixed frame; None: :func:`auto_base`) and the name the user gave."""

    model: ChainModel
    base: np.ndarray | None = None
    name: str | None = None


def arm_control_model(model: ControlModel, placed_arm: PlacedArm) -> ControlModel:
    """The controller's model of the cell with ``placed_arm`` in place of the PUMA 762: its
    limits, :data:`ARM_DEG_PER_COUNT`, no axis 4 → 5 coupling; platform, mount, tool and
    calibration as ``model``'s."""
    return replace(model, arm=placed_arm.arm, limits_deg=None, coupling=0.0,
                   axis_deg_per_count=np.full(6, ARM_DEG_PER_COUNT))


def arm_start_counts(placed_arm: PlacedArm) -> np.ndarray:
    """The simulated arm's axis counts at its start joints."""
    axis = placed_arm.arm.axis_from_q(placed_arm.q_start)
    return round_half_away(np.degrees(axis) / ARM_DEG_PER_COUNT).astype(np.int64)


def arm_io(cell: Cell, sensor: Sensor, placed_arm: PlacedArm, *, seed: int | None = 0,
           guard=None) -> InProcessIO:
    """The in-process cell carrying ``placed_arm`` (a :class:`SimulatedArm` of its model at its
    start joints), every command checked by ``guard`` first."""
    arm = placed_arm.arm
    return InProcessIO(cell, sensor, start_counts=arm_start_counts(placed_arm),
                       axis_deg_per_count=np.full(6, ARM_DEG_PER_COUNT), seed=seed,
                       arm=SimulatedArm(arm.model, placed_arm.q_start),
                       axis_offset=arm.axis_offset, guard=guard)
