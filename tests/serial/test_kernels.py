"""The compiled kernels against the plain NumPy reference, on random chains and inputs."""

import numpy as np
import pytest

import kinestat
from kinestat.errors import InputError
from kinestat.mechanism.chain import from_modified_dh, from_standard_dh
from kinestat.serial._reference import fk_reference, jacobian_reference
from kinestat.serial.fk import iter_fk
from kinestat.serial.jacobian import fk_and_jacobian


def random_chain(rng):
    n = int(rng.integers(1, 10))
    rows = np.c_[rng.uniform(-3, 3, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n),
                 rng.uniform(-3, 3, n)]
    kinds = list(rng.choice(["revolute", "prismatic", "screw"], n))
    pitches = [rng.uniform(-1, 1) if k == "screw" else 0.0 for k in kinds]
    build = from_standard_dh if rng.random() < 0.5 else from_modified_dh
    base = kinestat.fk(from_standard_dh(rows[:1]), rng.uniform(-3, 3, 1))
    return build(rows, kinds, pitches=pitches, base=base)


def test_kernels_match_reference(rng):
    for _ in range(40):
        m = random_chain(rng)
        q = rng.uniform(-4, 4, (int(rng.integers(1, 50)), m.n))
        np.testing.assert_allclose(kinestat.fk(m, q), fk_reference(m, q), atol=1e-12)
        np.testing.assert_allclose(kinestat.jacobian(m, q), jacobian_reference(m, q), atol=1e-12)
        np.testing.assert_allclose(kinestat.fk(m, q[0]), fk_reference(m, q[0]), atol=1e-12)
        np.testing.assert_allclose(kinestat.jacobian(m, q[0]), jacobian_reference(m, q[0]),
                                   atol=1e-12)
        T, J = fk_and_jacobian(m, q)
        np.testing.assert_allclose(T, fk_reference(m, q), atol=1e-12)
        np.testing.assert_allclose(J, jacobian_reference(m, q), atol=1e-12)


def test_leading_dimensions_and_layouts(rng):
    m = kinestat.load("puma762")
    q = rng.uniform(-3, 3, (4, 5, 6))
    np.testing.assert_allclose(kinestat.fk(m, q), fk_reference(m, q), atol=1e-12)
    qt = np.asfortranarray(q[:, 0, :])
    np.testing.assert_allclose(kinestat.fk(m, qt), fk_reference(m, qt), atol=1e-12)
    np.testing.assert_allclose(kinestat.fk(m, q[0, :, ::-1][:, ::-1]), fk_reference(m, q[0]),
                               atol=1e-12)
    assert kinestat.fk(m, [0, 1, 2, 3, 4, 5]).shape == (4, 4)
    assert kinestat.fk(m, np.zeros((0, 6))).shape == (0, 4, 4)


def test_iter_fk_streams_chunks(rng):
    m = kinestat.load("puma560")
    q = rng.uniform(-3, 3, (1000, 6))
    parts = list(iter_fk(m, q, chunk_rows=300))
    assert [r.start for r, _ in parts] == [0, 300, 600, 900]
    np.testing.assert_allclose(np.concatenate([p for _, p in parts]), fk_reference(m, q),
                               atol=1e-12)


@pytest.mark.parametrize("bad", [[np.nan, 0, 0, 0, 0, 0], [[0] * 6, [0, 0, np.inf, 0, 0, 0]]])
def test_nonfinite_rejected(bad):
    m = kinestat.load("puma560")
    with pytest.raises(InputError, match="NaN"):
        kinestat.fk(m, bad)
    with pytest.raises(InputError, match="NaN"):
        kinestat.jacobian(m, bad)


def test_wrong_shape_and_type():
    m = kinestat.load("puma560")
    with pytest.raises(InputError):
        kinestat.fk(m, np.zeros((3, 5)))
    with pytest.raises(InputError):
        kinestat.fk(m, "abc")


def test_single_configuration_fast_path_edge_cases(rng):
    """The direct entry point only takes contiguous float64 vectors; every other layout goes
    through the checked path, and all give the reference result."""
    m = kinestat.load("puma762")
    q = rng.uniform(-3, 3, 6)
    ro = q.copy()
    ro.setflags(write=False)
    raw = bytearray(6 * 8 + 1)
    unaligned = np.frombuffer(raw, dtype=np.float64, count=6, offset=1)
    strided = np.zeros(12)
    strided[::2] = q
    for variant in (q, ro, strided[::2], q.astype(np.float32).astype(np.float64), list(q)):
        v = np.array(variant, dtype=float)
        np.testing.assert_allclose(kinestat.fk(m, variant), fk_reference(m, v), atol=1e-12)
        np.testing.assert_allclose(kinestat.jacobian(m, variant), jacobian_reference(m, v),
                                   atol=1e-12)
    np.testing.assert_allclose(kinestat.fk(m, unaligned), fk_reference(m, np.zeros(6)), atol=1e-12)
    with pytest.raises(InputError):
        kinestat.fk(m, q[:5].copy())
    with pytest.raises(InputError, match="NaN"):
        kinestat.fk(m, np.r_[q[:5], np.nan])
    with pytest.raises(InputError, match="NaN"):
        kinestat.jacobian(m, np.r_[q[:5], np.inf])


def test_single_configuration_fast_path_is_bit_identical_and_errs_once(rng):
    """A float64 vector of any stride takes the compiled entry point; its result is bit for bit
    the checked path's (a list of the same numbers) and the batch kernel's row, and a wrong
    length or a NaN still gets the checked path's one error."""
    m = kinestat.load("puma560")
    Q = rng.uniform(-3, 3, (20, 6))
    strided = np.zeros((20, 12))
    strided[:, ::2] = Q
    T_batch, J_batch = kinestat.fk(m, Q), kinestat.jacobian(m, Q)
    for k in range(len(Q)):
        for v in (Q[k], strided[k, ::2], Q[k][::-1].copy()[::-1]):
            assert np.array_equal(kinestat.fk(m, v), kinestat.fk(m, list(Q[k])))
            assert np.array_equal(kinestat.fk(m, v), T_batch[k])
            assert np.array_equal(kinestat.jacobian(m, v), kinestat.jacobian(m, list(Q[k])))
            assert np.array_equal(kinestat.jacobian(m, v), J_batch[k])
    for f in (kinestat.fk, kinestat.jacobian):
        for bad in (np.zeros(5), np.zeros(7), np.zeros(0)):
            with pytest.raises(InputError, match="shape"):
                f(m, bad)
        with pytest.raises(InputError, match="NaN"):
            f(m, np.r_[Q[0, :5], np.nan])
        # a non-native byte order or another dtype is converted by the checked path
        assert np.array_equal(f(m, Q[0].astype(">f8")), f(m, Q[0]))
        assert np.array_equal(f(m, Q[0].astype(np.float32)), f(m, Q[0].astype(np.float32).tolist()))


def test_sincos_agrees_with_numpy_within_two_ulps(rng):
    """The kernels' branch-free sine-cosine pair against NumPy's (the reference's), over the
    joint range, large angles (the C-library fall-back), tiny ones and exact quadrants."""
    import numba as nb

    from kinestat.serial._sincos import LARGE, PIO2_1, PIO2_2, PIO2_3, sincos, sincos_block

    @nb.njit
    def both(x):
        s, c = np.empty_like(x), np.empty_like(x)
        sincos_block(x, s, c, x.shape[0])
        s1, c1 = np.empty_like(x), np.empty_like(x)
        for k in range(x.shape[0]):
            s1[k], c1[k] = sincos(x[k])
        return s, c, s1, c1

    x = np.concatenate([rng.uniform(-7, 7, 20000), rng.uniform(-1e4, 1e4, 5000),
                        rng.normal(0, 1e-9, 100), np.arange(-64, 65) * np.pi / 4,
                        [0.0, -0.0, LARGE, -LARGE, 1e300, 5e-324]])
    s, c, s1, c1 = both(x)
    assert np.array_equal(s, s1) and np.array_equal(c, c1)
    for got, want in ((s, np.sin(x)), (c, np.cos(x))):
        ulps = np.abs(got - want) / np.spacing(np.maximum(np.abs(want), 1e-300))
        assert ulps.max() <= 2.0
    # π/2 split in three: their sum is π/2 to far beyond double precision
    from fractions import Fraction

    pi = Fraction("3.14159265358979323846264338327950288419716939937510582097494459")
    err = Fraction(PIO2_1) + Fraction(PIO2_2) + Fraction(PIO2_3) - pi / 2
    assert abs(float(err)) < 1e-35
    s, c, _, _ = both(np.array([np.nan, np.inf, -np.inf]))
    assert np.isnan(s).all() and np.isnan(c).all()


def test_batches_over_many_blocks(rng):
    """Batches long enough for the parallel kernel (several blocks, a partial last one): the
    reference's values, the single-configuration kernels' bits, and a non-finite row anywhere
    rejected."""
    from kinestat.serial._kernels import _PARALLEL_MIN, BLOCK

    for _ in range(3):
        m = random_chain(rng)
        N = _PARALLEL_MIN + BLOCK + 37
        q = rng.uniform(-4, 4, (N, m.n))
        T, J = kinestat.fk(m, q), kinestat.jacobian(m, q)
        np.testing.assert_allclose(T, fk_reference(m, q), atol=1e-12)
        np.testing.assert_allclose(J, jacobian_reference(m, q), atol=1e-12)
        for k in (0, BLOCK - 1, BLOCK, N - 1):
            assert np.array_equal(kinestat.fk(m, q[k]), T[k])
            assert np.array_equal(kinestat.jacobian(m, q[k]), J[k])
        for row in (0, N - 1, int(rng.integers(N))):
            bad = q.copy()
            bad[row, int(rng.integers(m.n))] = rng.choice([np.nan, np.inf, -np.inf])
            with pytest.raises(InputError, match="NaN"):
                kinestat.fk(m, bad)
            with pytest.raises(InputError, match="NaN"):
                fk_and_jacobian(m, bad)


def test_single_calls_alternating_models_use_each_models_chain(rng):
    """The one-configuration path remembers the last model: calls alternating between models
    (same and different joint counts, one seen for the first time) each get their own chain."""
    models = [kinestat.load("puma560"), kinestat.load("puma762"), random_chain(rng),
              random_chain(rng)]
    for _ in range(3):
        for m in models:
            q = rng.uniform(-3, 3, m.n)
            np.testing.assert_allclose(kinestat.fk(m, q), fk_reference(m, q), atol=1e-12)
            np.testing.assert_allclose(kinestat.jacobian(m, q), jacobian_reference(m, q),
                                       atol=1e-12)
        models.append(random_chain(rng))
    with pytest.raises(InputError, match="ChainModel"):  # never the memo's empty slot
        kinestat.fk(None, np.zeros(6))
