"""The PUMA 762 is one package (kinestat.robots.puma762): its old import paths re-export the same
objects, and its IK method reaches ik_all through the generic registry."""

from __future__ import annotations

import importlib
import subprocess
import sys

import numpy as np
import pytest

import kinestat
from kinestat.errors import ModelError
from kinestat.robots.puma762 import closed_form
from kinestat.serial import ik_methods

# deprecated path -> (new module, names that must be the very same objects)
OLD_PATHS = {
    "kinestat.serial.puma762": ("kinestat.robots.puma762.closed_form",
                                ["forward", "reverse", "select", "AXIS_LIMITS_DEG", "_A", "_S"]),
    "kinestat.serial.puma762.params": ("kinestat.robots.puma762.params", ["AXIS_OFFSET"]),
    "kinestat.serial.puma762.forward": ("kinestat.robots.puma762.forward", ["frame6"]),
    "kinestat.serial.puma762.reverse": ("kinestat.robots.puma762.reverse", ["reverse_pose"]),
    "kinestat.serial.puma762.selection": ("kinestat.robots.puma762.selection", ["select"]),
    "kinestat.serial.analytic.thesis_puma762": ("kinestat.robots.puma762.analytic",
                                                ["puma762_chain", "ik_all_thesis"]),
    "kinestat.hardware.puma762_axes": ("kinestat.robots.puma762.axes",
                                       ["AXIS_DEG_PER_COUNT", "axis45_compensation"]),
    "kinestat.hardware.puma762_homing": ("kinestat.robots.puma762.homing", ["HOME_COUNTS"]),
    "kinestat.sim.puma762_robot": ("kinestat.robots.puma762.layout", ["layout"]),
    "kinestat.control.arm": ("kinestat.robots.puma762.arm", ["Puma762Arm", "THESIS_ARM"]),
}


@pytest.mark.parametrize("old", sorted(OLD_PATHS))
def test_old_import_paths_give_the_same_objects(old):
    new, names = OLD_PATHS[old]
    a, b = importlib.import_module(old), importlib.import_module(new)
    for name in names:
        assert getattr(a, name) is getattr(b, name), f"{old}.{name}"
    if old != "kinestat.control.arm":  # a whole-module re-export: every public name
        assert set(b.__all__) <= set(a.__all__)


def test_the_old_package_keeps_its_functions_when_a_submodule_is_imported():
    code = ("import kinestat.serial.puma762.forward, kinestat.serial.puma762.reverse; "
            "from kinestat.serial import puma762 as P; "
            "print(callable(P.forward), callable(P.reverse), P.forward.__module__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["True", "True", "kinestat.robots.puma762.forward"]


def test_the_puma762_method_is_registered_not_named_by_the_dispatch():
    # the generic methods do not name the robot; it is a registered method
    from kinestat.serial.analytic import METHODS

    assert "puma762" not in METHODS and "puma762" in ik_methods.registered()
    m = kinestat.load("puma762")
    q = np.array([0.3, -0.2, 0.4, 0.5, -0.6, 0.7])
    res = kinestat.ik_all(m, closed_form.forward(q).pose, method="puma762")
    assert res.method == "puma762"
    # one of the valid solutions is q (the closed form's branches are its own computation;
    # kinestat.fk checks every slot inside ik_all)
    d = np.abs(np.angle(np.exp(1j * (res.solutions() - q)))).max(axis=1)
    assert d.min() < 1e-9


def test_a_method_that_does_not_apply_is_refused_by_name():
    with pytest.raises(ModelError, match="'puma762' applies only to the PUMA 762's geometry"):
        kinestat.ik_all(kinestat.load("puma560"), np.eye(4), method="puma762")
    with pytest.raises(ModelError, match="expected one of .*'puma762'"):
        kinestat.ik_all(kinestat.load("puma560"), np.eye(4), method="no-such-method")


def test_a_registered_method_is_dispatched(monkeypatch):
    calls = []

    def solve(model, T, *, tol, backend):
        calls.append((model.name, T.shape, tol, backend))
        return kinestat.ik_all(model, T)

    monkeypatch.setattr(ik_methods, "_METHODS", dict(ik_methods._METHODS))
    ik_methods.register(ik_methods.IKMethod("ur5-test", lambda m: m.name == "ur5", solve,
                                            "a model named ur5"))
    m = kinestat.load("ur5")
    res = kinestat.ik_all(m, kinestat.fk(m, np.zeros(6)), method="ur5-test", tol=1e-8)
    assert calls == [("ur5", (1, 4, 4), 1e-8, "numba")] and int(res.n_solutions) > 0


def test_importing_the_robot_package_is_cheap():
    code = ("import sys, kinestat.robots; "
            "print(sorted(m for m in ('numba', 'scipy', 'kinestat.robots.puma762.closed_form') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"
