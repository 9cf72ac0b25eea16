"""Python forms of C++ core and RBPF helpers: Rng.reseed / normal(mu, sigma), the generators' saved
states and pickling, log_normalize,
gaussian_log_pdf_chol, is_spd / is_spsd, are_log_weights, SigmaScheme from its fields,
encode/decode_situation, Iukf.motion / dim."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy import special, stats

from nlosloc import core, models, noise, rbpf, situation


def test_rng_reseed_and_scaled_normal() -> None:
    r = core.Rng(1, 2)
    r.normal()
    r.reseed(7, 3)
    fresh = core.Rng(7, 3)
    assert [r() for _ in range(5)] == [fresh() for _ in range(5)]
    a, b = core.Rng(9), core.Rng(9)
    assert a.normal(2.0, 3.0) == 2.0 + 3.0 * b.normal()
    assert a.normal(2.0, 0.0) == 2.0
    with pytest.raises(ValueError, match="sigma: expected a finite standard deviation >= 0"):
        a.normal(0.0, -1.0)
    with pytest.raises(ValueError, match="mu: expected a finite mean"):
        a.normal(np.inf, 1.0)
    with pytest.raises(ValueError, match=r"stream: expected an integer in \[0, 2\*\*64 - 1\]"):
        a.reseed(1, -1)


def test_generator_states_and_pickles_continue_the_sequence() -> None:
    import pickle

    r = core.Rng(4, 1)
    r.normal()  # keeps the second variate: part of the state
    words = r.save_state()
    assert len(words) == 6 and words[4] == 1
    other = core.Rng(99)
    other.restore_state(words)
    copy = pickle.loads(pickle.dumps(r))
    assert other.normal() == copy.normal() == r.normal()
    assert [other() for _ in range(5)] == [copy() for _ in range(5)] == [r() for _ in range(5)]
    b = core.BatchRng(core.Rng(8))
    b.uniform()  # part of its buffer used
    bw = b.save_state()
    assert len(bw) == 81 and bw[-1] == 1
    c = pickle.loads(pickle.dumps(b))
    np.testing.assert_array_equal(c.normals(300), b.normals(300))
    assert c() == b()
    before = other.save_state()
    count = r"words: expected 6 64-bit words \(save_state\(\)\), got 5"
    with pytest.raises(ValueError, match=count):
        other.restore_state(words[:5])
    with pytest.raises(ValueError, match="words: no generator state"):
        other.restore_state([0, 0, 0, 0, 0, 0])
    with pytest.raises(ValueError, match="words: no generator state"):
        b.restore_state(bw[:-1] + [65])  # the buffer holds 64 words
    assert other.save_state() == before


def test_log_normalize_against_scipy() -> None:
    v = np.array([-1.0, 2.0, -np.inf, 0.5])
    out, z = core.log_normalize(v)
    assert z == pytest.approx(special.logsumexp(v), abs=1e-12)
    np.testing.assert_allclose(out, v - special.logsumexp(v), atol=1e-12)
    assert np.exp(out).sum() == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_array_equal(v, [-1.0, 2.0, -np.inf, 0.5])  # the input is not modified
    dead = np.full(3, -np.inf)
    out, z = core.log_normalize(dead)
    assert z == -np.inf
    np.testing.assert_array_equal(out, dead)


def test_gaussian_log_pdf_chol_against_scipy() -> None:
    S = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]])
    x = np.array([0.3, -1.2, 2.0])
    L = np.linalg.cholesky(S)
    expected = stats.multivariate_normal(np.zeros(3), S).logpdf(x)
    assert core.gaussian_log_pdf_chol(L, x) == pytest.approx(expected, abs=1e-12)
    with pytest.raises(ValueError, match="L: expected shape"):
        core.gaussian_log_pdf_chol(L[:2, :2], x)
    with pytest.raises(ValueError, match="L: expected a lower-triangular Cholesky factor"):
        core.gaussian_log_pdf_chol(L.T, x)
    with pytest.raises(ValueError, match="L: expected a lower-triangular Cholesky factor"):
        core.gaussian_log_pdf_chol(-L, x)


def test_is_spd() -> None:
    S = np.array([[4.0, 1.0], [1.0, 3.0]])
    assert core.is_spd(S)
    assert not core.is_spd(np.array([[1.0, 2.0], [2.0, 1.0]]))  # indefinite
    assert not core.is_spd(np.array([[4.0, 1.0], [1.1, 3.0]]))  # not symmetric
    assert core.is_spd(np.array([[4.0, 1.0], [1.1, 3.0]]), rel_tol=0.1)
    assert not core.is_spd(np.ones((2, 3)))
    assert not core.is_spd(np.array([[np.nan, 0.0], [0.0, 1.0]]))


def test_is_spsd_and_are_log_weights() -> None:
    singular = np.array([[1.0, 1.0], [1.0, 1.0]])  # PSD, rank 1
    assert core.is_spsd(singular) and not core.is_spd(singular)
    assert core.is_spsd(np.array([[4.0, 1.0], [1.0, 3.0]]))
    assert core.is_spsd(np.zeros((3, 3)))
    assert not core.is_spsd(np.array([[1.0, 2.0], [2.0, 1.0]]))  # eigenvalue -1
    assert not core.is_spsd(np.array([[1.0, 1.0], [1.1, 1.0]]))  # not symmetric
    assert core.is_spsd(np.array([[1.0, 1.0], [1.05, 1.1]]), rel_tol=0.1)
    assert not core.is_spsd(np.ones((2, 3)))
    assert not core.is_spsd(np.array([[np.inf, 0.0], [0.0, 1.0]]))
    assert core.are_log_weights(np.array([0.0, -np.inf, -3.5]))
    assert core.are_log_weights(np.zeros(0))
    assert not core.are_log_weights(np.array([0.0, np.nan]))
    assert not core.are_log_weights(np.array([np.inf, 0.0]))


def test_sigma_scheme_from_its_fields() -> None:
    import pickle

    k = core.SigmaScheme.Kind
    assert core.SigmaScheme() == core.SigmaScheme.scaled(1.0, 2.0, 0.0)
    assert core.SigmaScheme(k.Julier, kappa=1.5) != core.SigmaScheme.julier(1.5)  # beta 2 against 0
    # Huerta eq. (52) with beta = 3 (the factory fixes 2), n = 2, alpha = 0.5: lambda = 0.25 * 2 - 2
    # = -1.5, gamma = sqrt(0.5), Wm0 = -1.5 / 0.5 = -3, Wc0 = -3 + 1 - 0.25 + 3 = 0.75, Wi = 1.
    s = core.SigmaScheme(k.Huerta, 0.5, 3.0)
    w = s.weights(2)
    assert (w.wm0, w.wc0, w.wi) == pytest.approx((-3.0, 0.75, 1.0), rel=1e-14)
    assert w.gamma == pytest.approx(np.sqrt(0.5), rel=1e-14)
    t = pickle.loads(pickle.dumps(s))
    assert t == s and t.weights(2).wc0 == w.wc0  # pickled from its fields, beta kept
    assert hash(t) == hash(s) and len({t, s, core.SigmaScheme.huerta(0.5)}) == 2
    s.validate(2)
    bad = core.SigmaScheme(k.Scaled, alpha=1.5)  # built as the C++ aggregate: checked when used
    with pytest.raises(ValueError, match=r"alpha: expected a value in \(0, 1\], got 1.5"):
        bad.validate(2)
    with pytest.raises(ValueError, match=r"alpha: expected a value in \(0, 1\], got 1.5"):
        bad.weights(2)
    with pytest.raises(ValueError, match="kappa: expected n \\+ kappa > 0"):
        core.SigmaScheme(k.Julier, kappa=-3.0).validate(2)
    with pytest.raises(ValueError, match="dimension n must be > 0"):
        core.SigmaScheme.cubature().validate(0)


def test_generator_constants_and_default_batch() -> None:
    assert core.Rng.STATE_WORDS == len(core.Rng(3).save_state()) == 6
    assert core.BatchRng.LANES == 4 and core.BatchRng.BUFFER == 64
    assert core.BatchRng.STATE_WORDS == 4 * 4 + 64 + 1 == len(core.BatchRng().save_state())
    # BatchRng() is BatchRng(Rng()), as in C++
    np.testing.assert_array_equal(core.BatchRng().bits(8), core.BatchRng(core.Rng(0, 0)).bits(8))


def test_situation_keys() -> None:
    # base-N_z digits, anchor 0 least significant
    assert rbpf.encode_situation([1, 0, 1], 2) == 1 + 0 * 2 + 1 * 4
    assert rbpf.encode_situation([2, 1], 3) == 2 + 1 * 3
    np.testing.assert_array_equal(rbpf.decode_situation(5, 2, 3), [1, 0, 1])
    for s in itertools.product(range(3), repeat=3):
        key = rbpf.encode_situation(list(s), 3)
        np.testing.assert_array_equal(rbpf.decode_situation(key, 3, 3), s)
    assert sorted(
        rbpf.encode_situation(list(s), 3) for s in itertools.product(range(3), repeat=3)
    ) == list(range(27))
    with pytest.raises(
        ValueError, match=r"sight: expected conditions in \[0, 2\), got 2 at anchor 1"
    ):
        rbpf.encode_situation([0, 2], 2)
    with pytest.raises(ValueError, match="num_conditions: expected an integer >= 1, got 0"):
        rbpf.encode_situation([0], 0)
    with pytest.raises(ValueError, match="more than 2\\^62 situations"):
        rbpf.encode_situation([0] * 63, 2)
    with pytest.raises(ValueError, match="key: expected a key below N_z\\^B = 8, got 8"):
        rbpf.decode_situation(8, 2, 3)
    with pytest.raises(ValueError, match=r"key: expected an integer in \[0, 2\*\*64 - 1\]"):
        rbpf.decode_situation(-1, 2, 3)


def test_iukf_motion_and_dim() -> None:
    motion = models.ConstantVelocityClock2(0.01, 1.0, 1e-2)
    meas = models.MeasurementStack(models.ConstantVelocityClock2.layout(), np.eye(2) * 1000.0, 2)
    for b in range(2):
        meas.add_rtoa(b, [noise.Normal(0.0, 3.0), noise.Rayleigh.from_variance(5000.0)])
    sight = situation.SightProcess(situation.SightModel.speed_dependent(10.0, 10.0, 0.01), 2)
    quality = situation.QualityModel([noise.Beta(4.0, 1.5), noise.Beta(1.5, 4.0)])
    f = rbpf.Iukf(motion, meas, sight, quality, np.zeros(6), np.eye(6))
    assert f.dim == 6
    assert isinstance(f.motion, models.ConstantVelocityClock2)
    np.testing.assert_array_equal(f.motion.F, motion.F)


def test_measurement_stack_check_sight_and_has_angles() -> None:
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), np.eye(2) * 100.0, 3)
    st.add_toa(0, [noise.Normal(0.0, 1.0)] * 3)
    assert not st.has_angles
    st.add_aoa(1, [noise.Normal(0.0, 0.1)] * 3)
    assert st.has_angles
    st.check_sight([0, 2])
    with pytest.raises(
        ValueError, match=r"sight: expected conditions in \[0, 3\), got 3 at anchor 1"
    ):
        st.check_sight([0, 3])
    with pytest.raises(ValueError, match="sight: expected shape"):
        st.check_sight([0, 1, 2])
