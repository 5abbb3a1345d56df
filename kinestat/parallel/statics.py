"""Statics of the platform: leg lines, the line Jacobian, leg forces and wrenches, batched.

Vibhute 2011 §2.1.2, eqs. 2-2 to 2-8 (after Duffy). Leg ``i`` lies on the line
``{S_i; S0L_i} = {S_i; r_i × S_i}``, ``S_i`` the unit vector from the base point ``B_i`` to
the top point ``X_i`` and ``r_i = B_i`` (Appendix A, eq. A-7), all in the base frame with
moments about the base origin O0. The line Jacobian ``j`` has these lines as columns
(eq. 2-6), and ``w = j f`` (eq. 2-5), ``f = j⁻¹ w`` (eq. 2-8).

Sign convention (decided by physics, the thesis is silent):

* ``f_i > 0`` is **tension**: the leg pulls the top toward the base. A linear spring leg of
  constant ``k_i`` and free length ``l0_i`` at length ``l_i`` carries ``f_i = k_i (l_i − l0_i)``
  (stretched: tension; compressed: negative).
* ``w = j f`` is the **external wrench applied to the top platform** (by the tool, the
  workpiece, gravity...) that the legs balance, in ray coordinates ``[f; m_O0]``: force, then
  moment about the base origin O0, base-frame components. The wrench the legs apply to the top
  is ``−w``; the wrench the top (tool) applies to the environment is also ``−w``.

Check of the convention: push the top down (external force −z) and the legs shorten, f < 0
(compression), and ``j f`` points down too (legs' S_i point up). The thesis's MATLAB
(eq_wrench.m) sums the calibrated leg forces times the leg lines; its force maps are positive in
compression (see :mod:`kinestat.devices.calibration`), so its ``W_eq`` is our ``−w``.
"""

from __future__ import annotations

import numpy as np

from kinestat.errors import SingularityError
from kinestat.parallel.fk import check_lengths, fk_tracking
from kinestat.parallel.legs import leg_directions, leg_lines, line_jacobian
from kinestat.parallel.platform import Platform
from kinestat.parallel.singularity import singularity_measure
from kinestat.spatial.transforms import as_array
from kinestat.spatial.validate import as_number

# leg_directions, leg_lines and line_jacobian are defined in kinestat.parallel.legs
__all__ = [
    "leg_directions",
    "leg_lines",
    "line_jacobian",
    "jacobian_det",
    "spring_forces",
    "wrench_from_forces",
    "forces_from_wrench",
    "spring_wrench",
    "wrench_from_leg_lengths",
]


def jacobian_det(platform: Platform, pose) -> np.ndarray:
    """det j (..., ), in (length unit)³ — zero at singular poses."""
    return np.linalg.det(line_jacobian(platform, pose))


def spring_forces(platform: Platform, lengths) -> np.ndarray:
    """Leg tensions of linear springs ``f_i = k_i (l_i − l0_i)`` (Vibhute eq. 2-9), (..., 6)."""
    L = check_lengths(lengths)
    return platform.stiffness * (L - platform.free_lengths)


def wrench_from_forces(platform: Platform, pose, forces) -> np.ndarray:
    """Forward static analysis ``w = j f`` (Vibhute eqs. 2-3 to 2-5): tensions → external wrench."""
    f = as_array(forces, shape_tail=(6,), name="leg forces")
    return np.einsum("...ij,...j->...i", line_jacobian(platform, pose), f)


def forces_from_wrench(platform: Platform, pose, wrench, *, tol: float = 1e-9) -> np.ndarray:
    """Reverse static analysis ``f = j⁻¹ w`` (Vibhute eq. 2-8): external wrench → leg tensions.

    Raises:
        SingularityError: the pose is singular (dimensionless |det j| below ``tol``).
    """
    w = as_array(wrench, shape_tail=(6,), name="wrench")
    tol = as_number(tol, "tol", nonnegative=True)
    j = line_jacobian(platform, pose)
    m = singularity_measure(platform, pose)
    if np.any(m < tol):
        raise SingularityError(
            f"the pose is singular (dimensionless |det j| = {float(np.min(m)):.3g}): the leg "
            "lines are linearly dependent, so the legs cannot balance every wrench and the leg "
            "forces are not determined; move away from this configuration")
    return np.linalg.solve(j, w[..., None])[..., 0]


def spring_wrench(platform: Platform, pose) -> np.ndarray:
    """The external wrench ``[f; m_O0]`` (base frame) holding the top in equilibrium at ``pose``.

    ``w = j k (l − l0)``: zero at the home pose, the wrench the tool must receive from the
    environment for the springs to sit at ``pose``. Batched over poses (..., 4, 4) → (..., 6).
    """
    S, l = leg_directions(platform, pose)
    f = platform.stiffness * (l - platform.free_lengths)
    lines = np.concatenate([S, np.cross(platform.base_points, S)], axis=-1)
    return np.einsum("...i,...ij->...j", f, lines)


def wrench_from_leg_lengths(platform: Platform, lengths, previous_pose, *, forces=None,
                            tol: float = 1e-9):
    """The kinestatic sensor chain: leg lengths → pose (tracking FK) → external wrench.

    Args:
        lengths: (..., 6) measured leg lengths (e.g. from encoder counts via
            :func:`kinestat.devices.calibration.counts_to_lengths`).
        previous_pose: (..., 4, 4) the last known pose (start: ``platform.home_pose``).
        forces: (..., 6) measured leg tensions (e.g. ``counts_to_forces``, the thesis's
            calibrated maps); default the linear springs' ``k (l − l0)``.

    Returns:
        ``(pose, wrench)``: the pose of the top (tracking mode) and the external wrench
        ``[f; m_O0]`` on the top, base frame.
    """
    L = check_lengths(lengths)
    pose = fk_tracking(platform, L, previous_pose, tol=tol)
    f = platform.stiffness * (L - platform.free_lengths) if forces is None else forces
    return pose, wrench_from_forces(platform, pose, f)
