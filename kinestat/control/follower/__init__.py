"""Force + motion: slide the tool along an unknown workpiece holding the normal force.
(development package; see phases)"""

from kinestat.control.follower.config import (
    FollowConfig,
    FollowState,
    carry_check,
    default_travel_dir,
)
from kinestat.control.follower.phases import FOLLOW_STATES, decide_follow
from kinestat.control.follower.summary import follow_summary
from kinestat.control.follower.tuning import FollowTuning, derive_tuning

__all__ = ["FollowConfig", "FollowState", "FOLLOW_STATES", "FollowTuning", "decide_follow",
           "carry_check", "default_travel_dir", "derive_tuning", "follow_summary"]
