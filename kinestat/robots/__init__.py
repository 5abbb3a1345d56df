"""Robots: one package per robot, with everything that is that robot and nothing else.

- :mod:`kinestat.robots.puma762` — the PUMA 762 of Vibhute 2011: its closed-form kinematics,
  joint limits and axis convention, its analytic IK (the ``"puma762"`` method of
  :func:`kinestat.ik_all`), the controller's arm (:class:`~kinestat.robots.puma762.arm.Puma762Arm`
  behind :class:`kinestat.control.arm.Arm`), its encoder scales and axis 4 → 5 coupling, homing
  offsets and the physical layout of its index marks.

A robot is a consumer of the generic layers below (``serial``, ``mechanism``, ``spatial``):
what it adds to them it registers (its IK method with :mod:`kinestat.serial.ik_methods`).
Importing this package registers the built-in robots and loads nothing heavy (their modules
load on first use). Its kinematic model as a file is ``kinestat/data/models/NAME.toml``
(read by :mod:`kinestat.io`).
"""

from __future__ import annotations

from kinestat.robots import puma762 as puma762  # registers its IK method

__all__ = ["puma762"]
