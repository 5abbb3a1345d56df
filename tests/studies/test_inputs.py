"""Seeds and grid counts are checked when a study's spec is built (QA item 2): one clear error,
exit 2, no output directory; the same rules for every study, in Python and on the CLI."""

from __future__ import annotations

import pytest

from kinestat.cli.main import main
from kinestat.errors import InputError
from kinestat.studies import grids
from kinestat.studies.platform_design import platform_design_spec
from kinestat.studies.platform_range import platform_range_spec
from kinestat.studies.tolerance import tolerance_spec
from kinestat.studies.workspace import workspace_spec

BUILDERS = {
    "workspace": lambda **kw: workspace_spec("puma762", **kw),
    "platform-range": lambda **kw: platform_range_spec(None, **kw),
    "platform-design": lambda **kw: platform_design_spec(None, **kw),
    "tolerance": lambda **kw: tolerance_spec(None, **kw),
}


@pytest.mark.parametrize("study", sorted(BUILDERS))
@pytest.mark.parametrize("seed", [-1, -(2**70), 1.5, True])
def test_every_study_refuses_bad_seeds(study, seed):
    with pytest.raises(InputError, match="--seed must be a whole number"):
        BUILDERS[study](samples=4, seed=seed)


@pytest.mark.parametrize("study", sorted(BUILDERS))
def test_large_seeds_are_accepted_and_kept(study):
    seed = 2**80 + 1  # NumPy's SeedSequence takes any non-negative integer
    assert BUILDERS[study](samples=4, seed=seed)["seed"] == seed


@pytest.mark.parametrize("study", ["workspace", "platform-range", "platform-design"])
@pytest.mark.parametrize("grid", [0, 1, -3])
def test_every_grid_study_refuses_fewer_than_two_values(study, grid):
    kw = {"values": {"height": "50:70"}} if study == "platform-design" else {}
    with pytest.raises(InputError, match="at least 2 values per axis"):
        BUILDERS[study](grid=grid, **kw)


def test_design_grid_needs_a_range_to_apply_to():
    with pytest.raises(InputError, match="no parameter is given as a range"):
        platform_design_spec(None, grid=3)
    with pytest.raises(InputError, match="no parameter is given as a range"):
        platform_design_spec(None, values={"height": "50:70:3"}, grid=3)
    spec = platform_design_spec(None, values={"height": "50:70"}, grid=3)
    assert spec["values"]["height"] == [50.0, 60.0, 70.0]


def test_design_grid_and_samples_are_exclusive():
    with pytest.raises(InputError, match="not both"):
        platform_design_spec(None, values={"height": "50:70"}, grid=3, samples=5)


def test_sampling_entries():
    assert grids.sampling(4, None, 0, 2) == {"seed": 0, "mode": "grid", "grid": 4}
    with pytest.raises(InputError, match="exactly one"):
        grids.sampling(4, 10, 0, 2)
    with pytest.raises(InputError, match="at least 1"):
        grids.sampling(None, 0, 0, 2)


@pytest.mark.parametrize("args, message", [
    (["workspace", "--samples", "10", "--seed", "-1"], "--seed must be a whole number"),
    (["platform-range", "--samples", "10", "--seed", "-1"], "--seed must be a whole number"),
    (["platform-design", "--height", "50:70", "--samples", "2", "--seed", "-1"],
     "--seed must be a whole number"),
    (["tolerance", "--samples", "10", "--seed", "-1"], "--seed must be a whole number"),
    (["platform-design", "--grid", "0"], "at least 2 values"),
    (["platform-design", "--height", "50:70", "--grid", "1"], "at least 2 values"),
    (["platform-design", "--grid", "3"], "no parameter is given as a range"),
    (["platform-range", "--grid", "0"], "at least 2 values"),
])
def test_cli_one_line_exit_2_no_output(capsys, tmp_path, args, message):
    out = tmp_path / "out"
    code = main(["sweep", *args, "--output", str(out), "--no-plots", "--quiet"])
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert code == 2
    assert len(err) == 1 and err[0].startswith("kinestat: error:") and message in err[0]
    assert not out.exists()
