"""Real arms' URDF files from the ``example-robot-data`` test dependency (requirements/dev.txt),
with the end link each test uses. Offline: the package ships the files."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, distribution
from pathlib import Path

import pytest

_ROBOTS = "cmeel.prefix/share/example-robot-data/robots"

#: name -> (path inside example-robot-data, tip link or None for the only chain)
ARMS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "tool0"),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", "tool0"),
    "ur3": ("ur_description/urdf/ur3_robot.urdf", "tool0"),
    "kinova-j2s6s200": ("kinova_description/robots/kinova.urdf", "j2s6s200_end_effector"),
    "panda": ("panda_description/urdf/panda.urdf", "panda_hand_tcp"),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", None),
    "so100": ("so_arm_description/urdf/so100.urdf", None),
    "z1": ("z1_description/urdf/z1.urdf", None),
}


def robots_dir() -> Path:
    """The folder of example-robot-data's robots (skips the test when it is not installed)."""
    try:
        return Path(str(distribution("example-robot-data").locate_file(_ROBOTS)))
    except PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install -r requirements/dev.txt)")


def arm_path(name: str) -> Path:
    return robots_dir() / ARMS[name][0]
