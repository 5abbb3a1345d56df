"""The planar kinestatic example of Vibhute 2011 Fig. 2-10 (after Griffis & Duffy), batched.

A body carried by two actuated prismatic joints (pure translation along i and j, actuator
coordinates ``d = (d1, d2)``) holds a wheel through two springs B1C and B2C (constants k1, k2,
free lengths L01, L02). The wheel (centre C, radius ρ_w) rolls without friction on a rigid wall,
the line through ``wall_point`` with unit normal ``n`` (pointing out of the wall, toward the
wheel) and tangent ``t = (n_y, −n_x)`` (n is t turned +90°). With the wheel at arc position
``s`` along the wall, ``C = wall_point + s t + ρ_w n``. The wall can only push along n: the
contact force on the wheel is ``N n``, N ≥ 0.

Spring pivots ``B_i = d + b_i`` (``b_i`` fixed in the body), so the springs see only
``r = C − d``. With :func:`~kinestat.parallel.planar_springs.two_spring_force`
(Vibhute eq. 2-12) the wheel is in equilibrium when::

    F(r) = [c1 c2; s1 s2] [k1 (l1 − L01); k2 (l2 − L02)] = N n              (balance)

and a change of it follows eq. 2-24, ``δF = K δr`` with K of eqs. 2-14/2-15 (eq. 2-25, ``j k jᵀ``,
when the springs are at their free lengths, N = 0). The balance fixes ``r`` from N alone, so
``d = C(s) − r(N)`` (:func:`actuator_displacements`, the thesis's control objective).

Kinestatic decomposition (planar; the reciprocal product of a force and a translation is the dot
product, so Δ reduces to the identity): an actuator move ``δd`` splits into a twist of freedom
``δs t`` (the wheel slides, reciprocal to the wall's force n) and a twist of compliance
``−K⁻¹ n δN`` (the springs deflect to change the contact force)::

    δd = δs t − δN K⁻¹ n,   δN = −(nᵀ K⁻¹ n)⁻¹ nᵀ δd,   δs = tᵀ (δd + δN K⁻¹ n)

(:func:`wheel_response`, :func:`actuator_step`). Loaded or not, this 2×2 K is symmetric: the wheel
is a point, K is the Hessian of the springs' energy; see docs/seed-errata.md P8.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError, SingularityError, UnreachableError
from kinestat.parallel.planar_springs import two_spring_force, two_spring_stiffness
from kinestat.spatial.transforms import as_array

__all__ = [
    "WheelOnWall",
    "figure_2_10_example",
    "wheel_center",
    "unloaded_offset",
    "spring_offset",
    "actuator_displacements",
    "wheel_stiffness",
    "wheel_response",
    "actuator_step",
]


@dataclass(frozen=True)
class WheelOnWall:
    """Immutable model of Fig. 2-10; lengths in ``length_unit``, forces in ``force_unit``."""

    body_points: np.ndarray  #: (2, 2) b1, b2: the spring pivots in the body, from its origin
    stiffness: np.ndarray  #: (2,) k1, k2 (force per length)
    free_lengths: np.ndarray  #: (2,) L01, L02
    wheel_radius: float
    wall_point: np.ndarray  #: (2,) a point of the wall line
    wall_normal: np.ndarray  #: (2,) unit normal n, out of the wall toward the wheel
    length_unit: str = "mm"
    force_unit: str = "N"

    def __post_init__(self) -> None:
        b = as_array(self.body_points, shape_tail=(2, 2), name="body points")
        k = as_array(self.stiffness, shape_tail=(2,), name="spring constants")
        l0 = as_array(self.free_lengths, shape_tail=(2,), name="free lengths")
        n = as_array(self.wall_normal, shape_tail=(2,), name="wall normal")
        if b.shape != (2, 2) or np.any(k <= 0) or np.any(l0 <= 0) or self.wheel_radius < 0:
            raise InputError("WheelOnWall: body_points (2, 2), positive k and free lengths and a "
                             "non-negative wheel radius are required")
        if not abs(np.linalg.norm(n) - 1.0) < 1e-12:
            raise InputError(f"WheelOnWall: the wall normal must be a unit vector, got {n}")
        for name, v in (("body_points", b), ("stiffness", k), ("free_lengths", l0),
                        ("wall_normal", n),
                        ("wall_point", as_array(self.wall_point, shape_tail=(2,), name="wall"))):
            v = v.copy()
            v.setflags(write=False)
            object.__setattr__(self, name, v)

    @property
    def wall_tangent(self) -> np.ndarray:
        """t = (n_y, −n_x): the direction of increasing s along the wall (n is t turned +90°)."""
        return np.array([self.wall_normal[1], -self.wall_normal[0]])


def figure_2_10_example() -> WheelOnWall:
    """A Fig. 2-10 instance (our numbers; the thesis gives none): floor y = 0, body above.

    b1 = (−50, 0), b2 = (50, 0) mm; k1 = 2, k2 = 3 N/mm; L01 = 80, L02 = 70 mm; wheel radius
    20 mm; wall normal n = (0, 1).
    """
    return WheelOnWall(body_points=np.array([[-50.0, 0.0], [50.0, 0.0]]),
                       stiffness=np.array([2.0, 3.0]), free_lengths=np.array([80.0, 70.0]),
                       wheel_radius=20.0, wall_point=np.zeros(2), wall_normal=np.array([0.0, 1.0]))


def wheel_center(model: WheelOnWall, s) -> np.ndarray:
    """C (..., 2) of the wheel in contact at arc position ``s`` (...,) along the wall."""
    s = as_array(s, name="wheel position s")
    return (model.wall_point + s[..., None] * model.wall_tangent
            + model.wheel_radius * model.wall_normal)


def unloaded_offset(model: WheelOnWall) -> np.ndarray:
    """``r = C − d`` (2,) with both springs at their free lengths (N = 0), wall side of b1b2.

    Closed form: the intersection of the circles |r − b_i| = L0_i on the side of −n.
    """
    b1, b2 = model.body_points
    L1, L2 = model.free_lengths
    e = b2 - b1
    D = float(np.linalg.norm(e))
    if D == 0.0 or D > L1 + L2 or D < abs(L1 - L2):
        raise InputError(f"the free lengths {L1:g}, {L2:g} cannot meet across |b2 − b1| = {D:g}")
    u = e / D
    a = (L1**2 - L2**2 + D**2) / (2 * D)
    h = np.sqrt(max(L1**2 - a**2, 0.0))
    perp = np.array([-u[1], u[0]])
    if perp @ model.wall_normal > 0:
        perp = -perp
    return b1 + a * u + h * perp


def spring_offset(model: WheelOnWall, N, *, tol: float = 1e-12, max_iter: int = 50) -> np.ndarray:
    """``r = C − d`` (..., 2) at which the springs balance the contact force ``N n`` (eq. 2-12).

    Newton on eq. 2-12 with K of eqs. 2-14/2-15 from :func:`unloaded_offset`; N (...,) in the
    force unit. Raises UnreachableError when it does not converge (the springs buckle).
    """
    N = as_array(N, name="contact force N")
    target = N[..., None] * model.wall_normal
    r = np.broadcast_to(unloaded_offset(model), N.shape + (2,)).copy()
    scale = np.maximum(1.0, np.abs(N))
    for _ in range(max_iter):
        res = target - two_spring_force(model.body_points, r, model.stiffness,
                                        model.free_lengths)
        if np.all(np.linalg.norm(res, axis=-1) <= tol * scale):
            return r
        K = two_spring_stiffness(model.body_points, r, model.stiffness, model.free_lengths)
        r = r + np.linalg.solve(K, res[..., None])[..., 0]
    raise UnreachableError(f"no spring equilibrium for contact force(s) {np.ravel(N)[:4]}… "
                           f"{model.force_unit}: the springs may buckle under this load")


def actuator_displacements(model: WheelOnWall, s, N) -> np.ndarray:
    """Actuator coordinates ``d = (d1, d2)`` (..., 2) putting the wheel at ``s`` with force N.

    ``d = C(s) − r(N)`` (Vibhute §2.1.3.3, the control objective of Fig. 2-10).
    """
    s, N = np.broadcast_arrays(as_array(s, name="wheel position s"),
                               as_array(N, name="contact force N"))
    return wheel_center(model, s) - spring_offset(model, N)


def wheel_stiffness(model: WheelOnWall, N) -> np.ndarray:
    """K (..., 2, 2) of eq. 2-24 at contact force N: ``δF = K δr`` (eqs. 2-14/2-15; 2-25 at N=0)."""
    r = spring_offset(model, N)
    return two_spring_stiffness(model.body_points, r, model.stiffness, model.free_lengths)


def _compliance_normal(model: WheelOnWall, N) -> np.ndarray:
    K = wheel_stiffness(model, N)
    c = np.linalg.solve(K, np.broadcast_to(model.wall_normal, K.shape[:-1])[..., None])[..., 0]
    g = c @ model.wall_normal  # nᵀ K⁻¹ n
    if np.any(np.abs(g) <= 1e-12 * np.linalg.norm(c, axis=-1)):
        raise SingularityError("nᵀ K⁻¹ n = 0: the springs cannot change the contact force")
    return c


def wheel_response(model: WheelOnWall, N, delta_d) -> tuple[np.ndarray, np.ndarray]:
    """(δs, δN): the wheel's slide and the contact force change for a small actuator move δd.

    The planar kinestatic decomposition ``δd = δs t − δN K⁻¹ n`` (Griffis & Duffy), linear in δd.
    """
    dd = as_array(delta_d, shape_tail=(2,), name="actuator move")
    c = _compliance_normal(model, N)
    dN = -(dd @ model.wall_normal) / (c @ model.wall_normal)
    ds = (dd + dN[..., None] * c) @ model.wall_tangent
    return ds, dN


def actuator_step(model: WheelOnWall, N, delta_s, delta_N) -> np.ndarray:
    """The actuator move δd (..., 2) = ``δs t − δN K⁻¹ n`` for a wanted slide and force change."""
    c = _compliance_normal(model, N)
    ds = as_array(delta_s, name="slide")
    dN = as_array(delta_N, name="force change")
    return ds[..., None] * model.wall_tangent - dN[..., None] * c
