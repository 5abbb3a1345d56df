"""The kinestatic cell as a MuJoCo scene, built from kinestat's own models (no hand-written XML).

:func:`build_scene` writes the MJCF of one cell and compiles it (``mujoco`` is imported here,
on first use: only ``kinestat control --sim mujoco`` pays for it):

* the arm: a :class:`~kinestat.mechanism.chain.ChainModel` ``C0 · Z(q1) · C1 · … · Z(q6) · C6``
  becomes nested bodies — body ``i``'s frame is joint ``i``'s frame (``base · C0 · Z(q1) · …
  · C(i−1)``), its hinge (or slide) about local z, its range the model's limits; body ``i+1``
  sits at ``C_i`` in body ``i``; the flange frame is a site at ``C6`` in body 6. Each link's
  mass is a capsule of :attr:`SceneParams.link_radius` from its frame to the next
  (:attr:`SceneParams.link_density`); joints are driven by position actuators whose gains
  come from the joint-space inertia at the start pose (:attr:`SceneParams.servo_hz`,
  critically damped). A screw joint (pitch ≠ 0) has no MuJoCo equivalent: refused.
* the platform: the base plate is welded to the flange through ``Cell.mount``; the top plate
  and the tool are one free body (:attr:`SceneParams.top_mass` and its inertia as a disc plus
  the tool rod); each leg is a spatial tendon between ball-joint sites (the base and top
  attachment points), its force the TRUE leg law applied by the plant every step
  (:mod:`kinestat.sim.mujoco_plant`) through a tendon actuator, with a dashpot
  (:attr:`SceneParams.leg_damping_ratio`). The tool tip is a sphere of
  :attr:`SceneParams.tip_radius` whose foremost point along the tool axis is the cell's tip.
* the workpiece: ``Workpiece`` (a plane) as a box whose face is the plane, ``Cylinder`` as a
  cylinder geom; MuJoCo's own contact with Coulomb friction μ (elliptic cone, ``condim`` 3,
  or 1 when μ = 0; the no-slip solver so that a tip inside the cone sticks). Rigid: a stiff
  contact (:attr:`SceneParams.contact_timeconst`). With a ``stiffness`` (N/mm, the
  workpiece's attribute or :func:`build_scene`'s argument) the workpiece body rides on slide
  joints with that spring along its normal (plane) or across its axis (cylinder), critically
  damped with :attr:`SceneParams.workpiece_mass`.

Units: SI inside MuJoCo (m, kg, s, N); kinestat's mm and N are converted at this boundary
(:data:`M_PER_MM`). Gravity is on (−z of the fixed frame).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kinestat.errors import InputError, ModelError
from kinestat.mechanism.chain import ChainModel
from kinestat.mechanism.joints import JointKind
from kinestat.sim.contact import Cell, Workpiece
from kinestat.sim.surface import Cylinder
from kinestat.spatial.transforms import apply
from kinestat.spatial.validate import frozen

__all__ = ["M_PER_MM", "SceneParams", "Scene", "build_scene", "scene_xml", "load_mujoco",
           "length_scale"]

M_PER_MM = 1e-3
"""Metres per millimetre: kinestat's lengths (mm) to MuJoCo's (m)."""

_UNITS_M = {"mm": 1e-3, "m": 1.0, "cm": 1e-2, "in": 0.0254}


def load_mujoco():
    """The ``mujoco`` module, imported on first use (one clear error when it is missing)."""
    try:
        import mujoco  # lazy: only --sim mujoco pays for it
    except ImportError as exc:  # pragma: no cover - installed with the project
        raise InputError("--sim mujoco needs the 'mujoco' package (pip install mujoco; it is "
                         "in requirements/run.txt)") from exc
    return mujoco


@dataclass(frozen=True)
class SceneParams:
    """Physical parameters of the MuJoCo cell (SI units; docs/mujoco.md maps them to the
    thesis)."""

    timestep: float = 5e-4
    """Integration step (s): a tenth of the stiff contact's time constant or less."""
    top_mass: float = 0.35
    """Top plate + tool (kg): an aluminium plate of the top's size and a steel tool rod."""
    tip_radius: float = 1.0e-3
    """Radius of the tool's spherical tip (m)."""
    leg_damping_ratio: float = 0.5
    """Damping of the legs' dashpots as a ratio of the top's critical damping on one leg."""
    top_weight: bool = False
    """Gravity on the top + tool; the controller is then given their weight and centre of
    mass (:meth:`Scene.top_load`), as a user declares a tool's. Off by default: weightless, as
    the thesis's model and the built-in simulator (docs/mujoco.md, *Limits*)."""
    link_radius: float = 0.06
    """Radius of the arm's link capsules (m), for their mass and inertia."""
    link_density: float = 2700.0
    """Density of the arm's links (kg/m³: cast aluminium)."""
    servo_hz: float = 8.0
    """Closed-loop bandwidth of the arm's joint servos (Hz), critically damped."""
    servo_integral_hz: float = 0.8
    """Corner of the servos' integral action (Hz): removes the static error under load."""
    contact_timeconst: float = 2e-3
    """Time constant of a rigid workpiece's contact (s, MuJoCo ``solref``)."""
    impratio: float = 1.0
    """MuJoCo's ratio of frictional to normal constraint impedance (elliptic cones)."""
    noslip_iterations: int = 10
    """MuJoCo's no-slip solver passes: its soft friction otherwise creeps under a steady
    tangential load inside the cone (0.02 mm/s at |f_t| = 0.2 f_n, μ = 0.3), where a metal
    tip on a workpiece sticks (Coulomb)."""
    workpiece_mass: float = 0.5
    """Moving mass of a compliant workpiece's surface (kg)."""
    link_gravcomp: bool = True
    """The servos carry the links' weight (an industrial servo's gravity feed-forward and
    integral action); their remaining error comes from the platform's load."""

    def __post_init__(self) -> None:
        for name in ("timestep", "top_mass", "tip_radius", "link_radius", "link_density",
                     "servo_hz", "contact_timeconst", "workpiece_mass"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"MuJoCo scene: {name} must be a positive number, got {v!r}")


@dataclass(frozen=True, eq=False)
class Scene:
    """A compiled MuJoCo cell: ``model`` (``mujoco.MjModel``) and the names and ids the plant
    needs. ``q_start`` the arm's joints the scene was built at (radians or model lengths);
    ``leg_stiffness`` (6,) N/m at the free lengths (platform leg order)."""

    model: object
    xml: str
    cell: Cell
    arm: ChainModel
    params: SceneParams
    q_start: np.ndarray
    top_pose_start: np.ndarray
    workpiece_stiffness: float | None
    ids: dict = field(default_factory=dict)

    def top_load(self) -> tuple[float, np.ndarray, np.ndarray]:
        """What the legs carry besides the contact: ``(mass_kg, com_top_mm, gravity_m_s2)``,
        the top + tool's mass (0 when ``params.top_weight`` is off), their centre of mass in
        the top frame (mm) and the scene's gravity (fixed frame, m/s²)."""
        b = self.ids["top"]
        mass = float(self.model.body_mass[b]) if self.params.top_weight else 0.0
        com = np.asarray(self.model.body_ipos[b], float) / M_PER_MM
        return mass, com, np.asarray(self.model.opt.gravity, float).copy()

    @property
    def tip_radius_mm(self) -> float:
        """The radius of the tool's ball tip (mm), which the controller is told as a user
        declares a tool's tip."""
        return self.params.tip_radius / M_PER_MM


def length_scale(model: ChainModel) -> float:
    """Metres per unit of ``model``'s lengths."""
    try:
        return _UNITS_M[model.length_unit]
    except KeyError:
        raise ModelError(f"MuJoCo scene: arm {model.name!r} has length unit "
                         f"{model.length_unit!r}; one of {', '.join(_UNITS_M)} is needed") from None


def _f(v) -> str:
    return " ".join(f"{float(x):.17g}" for x in np.ravel(v))


def _quat(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation matrix (scipy's, reordered)."""
    from scipy.spatial.transform import Rotation  # lazy: scipy only when a scene is built

    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return np.array([w, x, y, z])


def _pose_attr(T: np.ndarray, k: float) -> str:
    return f'pos="{_f(T[:3, 3] * k)}" quat="{_f(_quat(T[:3, :3]))}"'


def _check_arm(arm: ChainModel) -> None:
    if not isinstance(arm, ChainModel) or arm.n != 6:
        raise ModelError("MuJoCo scene: a 6-joint ChainModel is needed")
    screw = [i + 1 for i, c in enumerate(arm.kind_codes) if c == JointKind.SCREW]
    if screw:
        raise ModelError(f"MuJoCo cannot load arm {arm.name!r}: joint(s) {screw} are screw "
                         "joints (pitch != 0), which MuJoCo has no joint for")


def _arm_xml(arm: ChainModel, p: SceneParams, inner: str) -> str:
    """The arm's nested bodies with ``inner`` (the platform) inside the last one."""
    k = length_scale(arm)
    C = np.asarray(arm.constants)
    lo, hi = arm.lower, arm.upper
    body_T = [C[i] for i in range(6)]  # fk is C0 · Z(q1) · … · C6 (base and tool folded in)
    xml_close = ""
    out = []
    pris = np.asarray(arm.prismatic, dtype=bool)
    for i in range(6):
        nxt = C[i + 1][:3, 3] * k
        if np.linalg.norm(nxt) > 1e-9:
            geom = (f'<geom type="capsule" fromto="0 0 0 {_f(nxt)}" size="{p.link_radius:g}" '
                    f'density="{p.link_density:g}" contype="0" conaffinity="0" group="1"/>')
        else:
            geom = (f'<geom type="sphere" size="{p.link_radius:g}" density="{p.link_density:g}"'
                    ' contype="0" conaffinity="0" group="1"/>')
        scale = k if pris[i] else 1.0
        limited = np.isfinite(lo[i]) and np.isfinite(hi[i])
        rng = f' range="{lo[i] * scale:.17g} {hi[i] * scale:.17g}"' if limited else ""
        jtype = "slide" if pris[i] else "hinge"
        grav = ' gravcomp="1"' if p.link_gravcomp else ""
        out.append(f'<body name="link{i + 1}" {_pose_attr(body_T[i], k)}{grav}>'
                   f'<joint name="q{i + 1}" type="{jtype}" axis="0 0 1" limited='
                   f'"{"true" if limited else "false"}"{rng}/>{geom}')
        xml_close += "</body>"
    out.append(f'<body name="flange" {_pose_attr(C[6], k)}{grav}>'
               f'<site name="flange"/>{inner}</body>')
    return "".join(out) + xml_close


def _platform_xml(cell: Cell, p: SceneParams) -> tuple[str, str]:
    """(the base plate inside the flange body, the top + tool free body)."""
    plat = cell.platform
    M = np.asarray(cell.mount)
    bp = apply(M, plat.base_points) * M_PER_MM
    r_base = float(np.max(np.linalg.norm(plat.base_points[:, :2], axis=1))) * M_PER_MM
    base = [f'<body name="base_plate" {_pose_attr(M, M_PER_MM)} gravcomp="1">'
            f'<geom type="cylinder" size="{r_base:g} 0.003" pos="0 0 -0.003" mass="0.5" '
            'contype="0" conaffinity="0" group="1"/></body>']
    base += [f'<site name="b{i}" pos="{_f(bp[i])}" size="0.003"/>' for i in range(6)]
    return "".join(base), ""


def _top_xml(cell: Cell, p: SceneParams, T_top_world: np.ndarray) -> str:
    """The free top body (plate + tool rod + tip) at ``T_top_world`` (mm)."""
    plat = cell.platform
    tp = plat.top_points * M_PER_MM
    tip = np.asarray(cell.tool_tip) * M_PER_MM
    r_top = float(np.max(np.linalg.norm(plat.top_points[:, :2], axis=1))) * M_PER_MM
    # the sphere's foremost point along the top's axis is the cell's tip
    centre = tip - np.array([0.0, 0.0, p.tip_radius])
    m_rod = 0.15 * p.top_mass
    m_plate = p.top_mass - m_rod
    rod = (f'<geom type="capsule" fromto="0 0 0 {_f(centre)}" size="0.005" '
           f'mass="{m_rod:g}" contype="0" conaffinity="0" group="1"/>')
    grav = "" if p.top_weight else ' gravcomp="1"'
    sites = "".join(f'<site name="t{i}" pos="{_f(tp[i])}" size="0.003"/>' for i in range(6))
    return (f'<body name="top" {_pose_attr(T_top_world, M_PER_MM)}{grav}><freejoint name="top"/>'
            f'<geom type="cylinder" size="{r_top:g} 0.003" pos="0 0 -0.003" mass="{m_plate:g}"'
            f' contype="0" conaffinity="0" group="1"/>{rod}'
            f'<geom name="tip" type="sphere" size="{p.tip_radius:g}" pos="{_f(centre)}" '
            'mass="1e-4" contype="2" conaffinity="2" {fr}/>'
            f'<site name="tip" pos="{_f(tip)}" size="0.001"/>{sites}</body>')


def _frame_with_z(z: np.ndarray) -> np.ndarray:
    z = z / np.linalg.norm(z)
    a = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(a, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _workpiece_xml(wp, stiffness: float | None, p: SceneParams, fr: str) -> str:
    """The workpiece body (fixed, or on springs when ``stiffness`` N/mm is given)."""
    T = np.eye(4)
    if isinstance(wp, Cylinder):
        T[:3, :3] = _frame_with_z(np.asarray(wp.axis))
        T[:3, 3] = wp.point
        geom = (f'<geom name="workpiece" type="cylinder" size="{wp.radius * M_PER_MM:.17g} 2"'
                f' contype="2" conaffinity="2" {fr}/>')
        slides = ("1 0 0", "0 1 0")  # across the axis
    elif isinstance(wp, Workpiece):
        T[:3, :3] = _frame_with_z(np.asarray(wp.normal))
        T[:3, 3] = wp.point
        geom = ('<geom name="workpiece" type="box" size="2 2 0.05" pos="0 0 -0.05" '
                f'contype="2" conaffinity="2" {fr}/>')
        slides = ("0 0 1",)  # along the normal
    else:
        raise InputError(f"MuJoCo scene: workpiece {type(wp).__name__} is not supported "
                         "(plane or cylinder)")
    if stiffness is None:
        return f'<body name="workpiece" {_pose_attr(T, M_PER_MM)}>{geom}</body>'
    k = float(stiffness) / M_PER_MM  # N/mm -> N/m
    c = 2.0 * math.sqrt(k * p.workpiece_mass)  # critically damped surface
    joints = "".join(f'<joint name="wp{i}" type="slide" axis="{a}" stiffness="{k:.17g}" '
                     f'damping="{c:.17g}"/>' for i, a in enumerate(slides))
    return (f'<body name="workpiece" {_pose_attr(T, M_PER_MM)} gravcomp="1">{joints}'
            f'<inertial pos="0 0 0" mass="{p.workpiece_mass:g}" diaginertia="1 1 1"/>'
            f'{geom}</body>')


def _check_stiffness(stiffness) -> float | None:
    if stiffness is None:
        return None
    s = float(stiffness)
    if not (math.isfinite(s) and s > 0):
        raise InputError(f"workpiece stiffness must be a positive number of N/mm, got "
                         f"{stiffness!r}")
    return s


def scene_xml(cell: Cell, arm: ChainModel, q_start, top_pose_world, *,
              params: SceneParams | None = None, workpiece_stiffness=None) -> str:
    """The MJCF text of the cell (see the module docstring). ``top_pose_world``: the top's
    start pose in the fixed frame (mm)."""
    p = params or SceneParams()
    _check_arm(arm)
    wp = cell.workpiece
    mu = float(wp.friction)
    fr = (f'friction="{mu:g} 0 0" condim="3"' if mu > 0 else 'friction="0 0 0" condim="1"')
    stiff = _check_stiffness(workpiece_stiffness)
    solref = f'solref="{p.contact_timeconst:g} 1" solimp="0.99 0.999 0.0005 0.5 2"'
    base, _ = _platform_xml(cell, p)
    top = _top_xml(cell, p, np.asarray(top_pose_world, float)).replace("{fr}", fr)
    k_leg = np.asarray(cell.platform.stiffness) / M_PER_MM
    c_leg = 2.0 * p.leg_damping_ratio * np.sqrt(k_leg * p.top_mass / 6.0)
    tendons = "".join(f'<spatial name="leg{i}" damping="{c_leg[i]:.17g}"><site site="b{i}"/>'
                      f'<site site="t{i}"/></spatial>' for i in range(6))
    acts = "".join(f'<general name="leg{i}" tendon="leg{i}" ctrllimited="false"/>'
                   for i in range(6))
    acts += "".join(f'<position name="servo{i + 1}" joint="q{i + 1}" kp="1" kv="0" '
                    'ctrllimited="false"/>' for i in range(6))
    return (f'<mujoco model="kinestat-cell"><compiler angle="radian" autolimits="true"/>'
            f'<option timestep="{p.timestep:g}" integrator="implicitfast" cone="elliptic" '
            f'noslip_iterations="{int(p.noslip_iterations)}" impratio="{p.impratio:g}" '
            f'gravity="0 0 -9.81"/><default><geom {solref}/></default><worldbody>'
            f'{_arm_xml(arm, p, base)}{top}'
            f'{_workpiece_xml(wp, stiff, p, fr)}</worldbody><tendon>{tendons}</tendon>'
            f'<actuator>{acts}</actuator></mujoco>')


def build_scene(cell: Cell, arm: ChainModel, q_start, top_pose_world, *,
                params: SceneParams | None = None, workpiece_stiffness=None) -> Scene:
    """Compile the cell's scene (see the module docstring); the servo gains are set from the
    joint-space inertia at ``q_start``. ``workpiece_stiffness`` (N/mm) defaults to the
    workpiece's ``stiffness`` attribute (None: rigid)."""
    mujoco = load_mujoco()
    p = params or SceneParams()
    if workpiece_stiffness is None:
        workpiece_stiffness = getattr(cell.workpiece, "stiffness", None)
    xml = scene_xml(cell, arm, q_start, top_pose_world, params=p,
                    workpiece_stiffness=workpiece_stiffness)
    try:
        model = mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        raise ModelError(f"MuJoCo cannot load arm {arm.name!r}: {exc}") from exc
    ids = {
        "flange": mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "flange"),
        "tip_site": mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tip"),
        "tip": mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "tip"),
        "workpiece": mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "workpiece"),
        "top": mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "top"),
        "arm_qpos": np.array([model.jnt_qposadr[mujoco.mj_name2id(
            model, mujoco.mjtObj.mjOBJ_JOINT, f"q{i + 1}")] for i in range(6)]),
        "arm_dof": np.array([model.jnt_dofadr[mujoco.mj_name2id(
            model, mujoco.mjtObj.mjOBJ_JOINT, f"q{i + 1}")] for i in range(6)]),
        "top_qpos": int(model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT,
                                                            "top")]),
    }
    _set_servo_gains(mujoco, model, ids, q_start, arm, p)
    return Scene(model=model, xml=xml, cell=cell, arm=arm, params=p,
                 q_start=frozen(np.asarray(q_start, float), float),
                 top_pose_start=frozen(np.asarray(top_pose_world, float), float),
                 workpiece_stiffness=_check_stiffness(workpiece_stiffness), ids=ids)


def _set_servo_gains(mujoco, model, ids, q_start, arm: ChainModel, p: SceneParams) -> None:
    """kp = M_ii ω², kv = 2 M_ii ω (critically damped at ``servo_hz``) from the joint-space
    inertia at ``q_start`` (each joint's own, the others held)."""
    data = mujoco.MjData(model)
    q = np.asarray(q_start, dtype=float).copy()
    q[arm.prismatic] *= length_scale(arm)
    data.qpos[ids["arm_qpos"]] = q
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    w = 2.0 * math.pi * p.servo_hz
    for i in range(6):
        dof = int(ids["arm_dof"][i])
        m_ii = float(M[dof, dof])
        act = 6 + i
        model.actuator_gainprm[act, 0] = m_ii * w * w
        model.actuator_biasprm[act, 1] = -m_ii * w * w
        model.actuator_biasprm[act, 2] = -2.0 * m_ii * w
