"""Only what a command uses is compiled, and said when it takes over a second (issue 44): the
compile watch, the warm-up's sharing of groups between processes, one specialisation per
kernel whatever the caller's array flags."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

from kinestat.cli import _compile, _compile_watch


def test_the_watch_says_nothing_before_the_threshold(monkeypatch, capsys):
    monkeypatch.setattr(_compile_watch, "NOTICE_AFTER_S", 3600.0)
    w = _compile_watch._CompileWatch()
    w.on_start(None)
    w.on_start(None)  # a callee compiled inside its caller
    w.on_end(None)
    assert w.timer is not None  # still compiling the caller
    w.on_end(None)
    assert w.timer is None and not w.said and w.spent >= 0.0
    assert "compiling" not in capsys.readouterr().err


def test_the_watch_says_it_once_past_the_threshold(monkeypatch):
    monkeypatch.setattr(_compile_watch, "NOTICE_AFTER_S", 0.0)
    said = []
    w = _compile_watch._CompileWatch()
    monkeypatch.setattr(w, "say", lambda: (said.append(1), setattr(w, "said", True)))
    w.on_start(None)
    w.timer.join(10.0)  # due at once: the threshold is spent
    w.on_end(None)
    w.on_start(None)  # said already: no second timer
    assert w.timer is None
    w.on_end(None)
    assert said == [1]


def test_each_command_starts_its_own_count(monkeypatch):
    import numba  # noqa: F401  (the watch is installed once Numba is imported)

    _compile_watch.announce_compiles()
    w = _compile_watch._WATCH[0]
    w.spent, w.said = 5.0, True
    _compile_watch.announce_compiles()  # the next command
    assert w.spent == 0.0 and not w.said


def test_announcing_imports_no_numba_and_watches_once_numba_is_imported():
    code = ("import sys, json; from kinestat.cli import _compile_watch as w; "
            "w.announce_compiles(); before = 'numba' in sys.modules; import numba; "
            "print(json.dumps([before, len(w._WATCH)]))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout) == [False, 1]


def test_groups_are_dealt_once_each_costliest_first():
    groups = list(_compile.KERNELS)
    for jobs in (1, 2, 3):
        shares = _compile._shares(groups, jobs)
        assert len(shares) <= jobs
        assert sorted(g for s in shares for g in s) == sorted(groups)
        firsts = [s[0] for s in shares]
        costliest = sorted(groups, key=lambda g: -_compile._COST_S[g])[:len(shares)]
        assert sorted(firsts) == sorted(costliest)
    assert _compile.idle_cores() >= 1


def test_the_run_groups_are_warm_groups():
    assert set(_compile.RUN_GROUPS) <= set(_compile.KERNELS)


def test_the_puma_closed_form_compiles_once_for_any_array_flags():
    from kinestat.robots.puma762 import _kernels
    from kinestat.robots.puma762.closed_form import reverse

    p6 = np.zeros(3)
    ro = p6.copy()
    ro.flags.writeable = False
    strided = np.zeros(6)[::2]
    for tool6 in (p6, ro, strided, (0.0, 0.0, 0.0)):
        reverse([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], tool6)
    assert len(_kernels.reverse_vectors_one.signatures) == 1


def test_the_line_jacobian_compiles_once_for_any_array_flags():
    from kinestat.io.library import prototype
    from kinestat.parallel import _fk_kernels
    from kinestat.parallel.legs import line_jacobian_trusted

    p = prototype()
    T = np.array(p.home_pose, dtype=float)
    ro = T.copy()
    ro.flags.writeable = False
    J = [line_jacobian_trusted(p, x) for x in (T, ro, T[None])]
    assert np.array_equal(J[0], J[1]) and np.array_equal(J[0], J[2][0])
    assert len(_fk_kernels.line_jacobian_kernel.signatures) == 1
