"""The tuning of the press and of the move path every task shares, in one frozen object.

Each value has a unit, a meaning and the reason for its default: most follow from the
platform and the safety envelope (the prototype's 4° top range, the envelope's 30° per
command, the wrist's axis 4 → 5 coupling of 0.47) and the robot's count resolution (~0.02 mm
of tool travel per count, 0.2 N on this platform). The controller reads them from
:attr:`ControllerConfig.tuning <kinestat.control.controller.ControllerConfig>`; the follow
task has its own tuning (:mod:`kinestat.control.follow`). Physical constants and the thesis's
values are not tuning: they live with the model (:mod:`kinestat.control.model`,
:mod:`kinestat.hardware`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Tuning", "TUNING"]


@dataclass(frozen=True)
class Tuning:
    """The press's tuning and the shared move path's.

    Attributes:
        max_align_turn_deg: the largest align turn of S6 in one cycle (degrees). A workpiece
            met far off the tool axis is turned onto in steps: a 40° turn at once moves the
            wrist beyond the envelope's 30° per command. The default plane's first turn (4.8°)
            and the R = 200 mm cylinder's (13.5°, at a light first contact) are made at once.
        turn_retries: an align turn the envelope refuses because an axis would move more than
            its per-command step (a wrist near its singular pose swings axis 4 by 30–42° for a
            20° turn of S6) is tried again within the cycle at half the turn, up to this many
            times (count).
        push_turn_deg, push_left_deg: an align turn larger than ``push_turn_deg``, or one that
            leaves more than ``push_left_deg`` of misalignment (a turn cut at
            ``max_align_turn_deg``), is made without the force step's push along the new axis
            (degrees): the Newton step was computed at the old axis and the light first
            contact, and on a frictionless surface met far off the tool axis the push and the
            large turn together drove the force from about 1 N to 5–7 N in one cycle and the
            top past its 4° range (docs/control.md, "The press on curved and steep
            workpieces").
        overshoot_ratio: an align turn overshot when the next misalignment points back
            against it by more than this fraction of the turn
            (:func:`~kinestat.control.align.align_gain`; dimensionless).
        min_push_rate: the turned tool's push rate
            (:func:`~kinestat.control.align.turned_force`) is used for the step when it lies
            between this fraction of the axial point stiffness ``s6ᵀ K_tip s6`` and that
            stiffness (a sliding tip loads less than a pinned one); outside, the axial
            stiffness is kept (dimensionless).
        min_align_gain: the smallest fraction of the misalignment an align turn makes (five
            halvings). A frictionless R = 172 mm cylinder at 5.5 N lands a turn about 16 times
            its size past the normal (κ B ≈ 16): only a turn of about 1/17 of the
            misalignment lands on it (dimensionless).
        align_progress: a misalignment below this fraction of the one at the last progress is
            progress (:func:`~kinestat.control.align.align_stalled`; dimensionless).
        align_stall_cycles: contact cycles without progress after which turns cut to their
            floor stop the run (cycles).
        stuck_ratio: an align turn found the tip stuck when it removed less than this
            fraction of itself from the misalignment
            (:func:`~kinestat.control.align.turn_was_carried`; dimensionless).
        approach_step_fraction: each command of a long start move moves an axis at most this
            fraction of the envelope's ``max_joint_step_deg`` (18° of 30°): axis 5's motor
            step adds up to |coupling| (0.47) times axis 4's, so 1.47 × 18° < 30°
            (dimensionless).
        branch_change_deg: an axis that would move more than this in one command for a small
            move of the tool has changed inverse-kinematics branch; the envelope's refusal
            then says so (degrees).
        vernier_counts: the vernier's reach (counts): ± the first on axes 1–3 (they move the
            tool point along S6 by ~1–15 µm per count, so their combinations resolve ~0.1 µm),
            ± the second on the wrist axes 4–5; axis 6 as is (it turns the tool about its own
            axis).
        vernier_along_mm, vernier_lateral_mm, vernier_tilt_deg: the vernier's cost scales: a
            candidate's offset along S6 (mm), across it (mm) and its tilt (degrees) count
            alike at these sizes.
    """

    max_align_turn_deg: float = 20.0
    turn_retries: int = 3
    push_turn_deg: float = 10.0
    push_left_deg: float = 5.0
    overshoot_ratio: float = 0.5
    min_push_rate: float = 0.2
    min_align_gain: float = 1.0 / 32.0
    align_progress: float = 0.8
    align_stall_cycles: int = 12
    stuck_ratio: float = 0.5
    approach_step_fraction: float = 0.6
    branch_change_deg: float = 90.0
    vernier_counts: tuple[int, int] = (4, 1)
    vernier_along_mm: float = 1e-3
    vernier_lateral_mm: float = 0.05
    vernier_tilt_deg: float = 0.01

    @property
    def vernier_scales(self) -> tuple[float, float, float]:
        """(along S6 mm, across mm, tilt radians): the vernier's cost scales."""
        return (self.vernier_along_mm, self.vernier_lateral_mm,
                math.radians(self.vernier_tilt_deg))


TUNING = Tuning()
"""The default tuning (the values above)."""
