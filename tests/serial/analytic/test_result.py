"""The shared selection step: wrapping into limits and nearest-solution choice."""

from __future__ import annotations

import numpy as np

import kinestat
from kinestat.mechanism.chain import from_standard_dh
from kinestat.serial.analytic import ik_all, select_nearest, wrap_to_limits

from .arms import PI, ur5


def test_wrap_to_limits_property():
    rng = np.random.default_rng(0)
    q = rng.uniform(-10, 10, (500, 3))
    cur = rng.uniform(-3, 3, (500, 3))
    lo, hi = np.array([-4.0, -1.0, -7.0]), np.array([4.0, 1.0, 7.0])
    w, ok = wrap_to_limits(q, cur, lo, hi, [True, True, True])
    # same angle modulo 2π, inside limits where ok
    assert np.abs(np.mod(w - q + PI, 2 * PI) - PI).max() < 1e-9
    assert np.all(((w >= lo - 1e-12) & (w <= hi + 1e-12)) | ~ok)
    # nearest: no other shift inside the limits is nearer the current value
    for k in (-1, 1):
        alt = w + 2 * PI * k
        inside = (alt >= lo) & (alt <= hi)
        assert np.all(~(inside & ok) | (np.abs(alt - cur) >= np.abs(w - cur) - 1e-12))
    # a prismatic joint is never shifted
    w2, ok2 = wrap_to_limits([5.0], [0.0], [-1.0], [1.0], [False])
    assert w2[0] == 5.0 and not ok2[0]


def test_select_nearest_picks_the_least_motion_within_limits():
    model = ur5()
    rng = np.random.default_rng(1)
    q = rng.uniform(-PI, PI, (50, 6))
    res = ik_all(model, kinestat.fk(model, q))
    sel = select_nearest(model, res, current=q)
    assert sel.ok.all()
    # the generating configuration is a solution at zero motion
    np.testing.assert_allclose(sel.q, q, atol=1e-8)
    assert sel.motion.max() < 1e-7
    # brute force from another current configuration
    cur = rng.uniform(-PI, PI, 6)
    sel = select_nearest(model, res, current=cur)
    for i in range(q.shape[0]):
        sols = res.solutions((i,))
        d = np.abs(np.mod(sols - cur + PI, 2 * PI) - PI).sum(-1)
        assert abs(sel.motion[i] - d.min()) < 1e-9


def test_select_respects_limits():
    model = kinestat.load("puma560")
    lo, hi = model.lower, model.upper
    rng = np.random.default_rng(2)
    q = rng.uniform(lo, hi, (40, 6))
    res = ik_all(model, kinestat.fk(model, q))
    sel = select_nearest(model, res, current=np.zeros(6))
    assert sel.ok.all()
    assert np.all((sel.q >= lo - 1e-12) & (sel.q <= hi + 1e-12))
    np.testing.assert_allclose(kinestat.fk(model, sel.q), kinestat.fk(model, q), atol=1e-9)
    # with impossible limits nothing is selected
    tight = from_standard_dh(model.parameters, limits=[(0.0, 1e-9)] * 6, length_unit="m")
    res2 = ik_all(tight, kinestat.fk(model, q[:3]))
    sel2 = select_nearest(tight, res2)
    assert not sel2.ok.any() and np.all(sel2.index == -1) and np.isnan(sel2.q).all()


def test_select_on_singular_family_splits_motion():
    model = kinestat.load("puma560")
    q = np.array([0.3, 0.8, -0.4, 0.7, 0.0, -0.5])
    res = ik_all(model, kinestat.fk(model, q))
    cur = q + np.array([0, 0, 0, 0.2, 0, 0.2])
    sel = select_nearest(model, res, current=cur)
    assert sel.ok
    np.testing.assert_allclose(kinestat.fk(model, sel.q), kinestat.fk(model, q), atol=1e-9)
    assert sel.motion <= np.abs(cur - q).sum() + 1e-9


def test_a_first_ik_all_call_loads_neither_the_selection_step_nor_the_seven_joint_helpers():
    """Both load on first use (a fresh process: the first call's time), and the selection step's
    names resolve alike from the package and from ``result``, where they were before."""
    import subprocess
    import sys

    code = ("import sys, numpy as np, kinestat; m = kinestat.load('puma560'); "
            "kinestat.ik_all(m, kinestat.fk(m, np.full(6, 0.3))); "
            "print(' '.join(k for k in sys.modules if k.startswith('kinestat.serial.analytic.')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = out.stdout.split()
    assert "kinestat.serial.analytic.solve" in loaded
    assert "kinestat.serial.analytic.selection" not in loaded
    assert "kinestat.serial.analytic.locked" not in loaded
    from kinestat.serial import analytic
    from kinestat.serial.analytic import result, selection

    for name in ("Selection", "select_nearest", "wrap_to_limits"):
        assert getattr(result, name) is getattr(selection, name) is getattr(analytic, name)


def test_the_written_out_inits_are_the_dataclasses():
    """IKAllResult and HomeAxes write their __init__ out (a first call's time): the same
    parameters as the fields, in order and with their defaults, the values set, and frozen."""
    import dataclasses
    import inspect

    import pytest

    from kinestat.serial.analytic.geometry import HomeAxes
    from kinestat.serial.analytic.result import IKAllResult

    for cls in (IKAllResult, HomeAxes):
        fields = dataclasses.fields(cls)
        params = list(inspect.signature(cls.__init__).parameters.values())[1:]
        assert [p.name for p in params] == [f.name for f in fields]
        assert [p.default for p in params] == [
            inspect.Parameter.empty if f.default is dataclasses.MISSING else f.default
            for f in fields]
        values = {f.name: object() for f in fields}
        obj = cls(**values)
        assert all(getattr(obj, k) is v for k, v in values.items())
        assert all(getattr(cls(*values.values()), k) is v for k, v in values.items())
        with pytest.raises(dataclasses.FrozenInstanceError):
            obj.tol = 1.0
        other = object()
        name = fields[0].name
        assert getattr(dataclasses.replace(obj, **{name: other}), name) is other
    res = ik_all(ur5(), kinestat.fk(ur5(), np.full(6, 0.3)))
    assert repr(res).startswith("IKAllResult(q=array(")
