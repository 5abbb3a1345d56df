"""Index arithmetic, per-chunk random streams and the order-fixed reduction."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from kinestat.errors import InputError
from kinestat.studies import grids
from kinestat.studies import reduce as red


def test_grid_points_match_a_materialised_grid():
    lo, hi, n = np.array([-1.0, 0.0, 2.0]), np.array([1.0, 3.0, 5.0]), 4
    axes = [np.linspace(a, b, n) for a, b in zip(lo, hi, strict=True)]
    full = np.array(list(itertools.product(*axes)))
    total = grids.check_grid(n, 3)
    parts = [grids.grid_points(*grids.chunk_range(i, total, 7), lo, hi, n)
             for i in range(grids.chunk_count(total, 7))]
    got = np.concatenate(parts)
    assert got.shape == full.shape
    np.testing.assert_allclose(got, full, rtol=0, atol=1e-15)
    # both ends exactly
    assert set(got[:, 0]) >= {-1.0, 1.0} and got[:, 2].max() == 5.0


def test_grid_needs_two_values():
    with pytest.raises(InputError, match="at least 2"):
        grids.check_grid(1, 6)
    with pytest.raises(InputError, match="at least 2"):
        grids.check_grid(0, 2)


def test_chunk_streams_are_independent_and_repeatable():
    a = grids.chunk_rng(5, 3).normal(size=4)
    b = grids.chunk_rng(5, 3).normal(size=4)
    c = grids.chunk_rng(5, 4).normal(size=4)
    d = grids.chunk_rng(5, 3, grids.STREAM_POSES).normal(size=4)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c) and not np.allclose(a, d)


def test_merge_stats_equals_whole_array(rng):
    x = rng.normal(size=1000)
    parts = [red.stats(x[i:i + 97]) for i in range(0, 1000, 97)]
    s = red.finish_stats(red.merge_stats(parts))
    assert s["count"] == 1000 and s["min"] == x.min() and s["max"] == x.max()
    assert s["mean"] == pytest.approx(x.mean(), rel=1e-13)
    assert s["rms"] == pytest.approx(np.sqrt(np.mean(x * x)), rel=1e-13)
    # the fixed order makes it bitwise repeatable
    assert red.merge_stats(parts) == red.merge_stats(list(parts))


def test_histograms_merge_exactly(rng):
    x = rng.uniform(-0.5, 2.5, size=500)
    e = np.linspace(0, 2, 11)
    parts = [red.histogram(x[i:i + 50], e) for i in range(0, 500, 50)]
    h = red.merge_histograms(parts)
    assert h["counts"] == np.histogram(x, e)[0].tolist()
    assert h["below"] == int(np.sum(x < 0)) and h["above"] == int(np.sum(x > 2))


def test_parse_values():
    assert grids.parse_values("1,2.5", "p") == [1.0, 2.5]
    assert grids.parse_values("0:1", "p", grid=3) == [0.0, 0.5, 1.0]
    with pytest.raises(InputError, match="needs a count"):
        grids.parse_values("0:1", "p")
    with pytest.raises(InputError, match="cannot read"):
        grids.parse_values("a,b", "p")
