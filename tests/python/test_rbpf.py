"""nlosloc.rbpf: RBPF (classical, reordered), joint PF, IUKF, merge/resampling helpers; and
nlosloc.bounds.gcrb_rtoa."""

import platform

import numpy as np
import pytest

from nlosloc import bounds, models, noise, rbpf, situation

ANCHORS = np.array([[3000 * np.cos(b * np.pi / 3), 3000 * np.sin(b * np.pi / 3)] for b in range(6)])
MOTION = models.ConstantVelocityClock2(0.01, 1.0, 1e-2)
X0 = np.zeros(6)
P0 = np.diag([25.0, 25.0, 10.0, 1.0, 1.0, 10.0])


def stack():
    st = models.MeasurementStack(models.ConstantVelocityClock2.layout(), ANCHORS, 2)
    for b in range(6):
        st.add_rtoa(b, [noise.Normal(0.0, np.sqrt(10.0)), noise.Rayleigh.from_variance(5000.0)])
    return st


SIGHT = situation.SightProcess(situation.SightModel.speed_dependent(10.0, 10.0, 0.01), 6)
QUALITY = situation.QualityModel([noise.Beta(4.0, 1.5), noise.Beta(1.5, 4.0)])


def track(steps=100, seed=0):
    rng = np.random.default_rng(seed)
    s = rng.integers(0, 2, 6)
    x = np.array([0.0, 0.0, 0.0, 1.0, 0.5, 0.0])
    Y, Q_obs, S = [], [], []
    for _ in range(steps):
        x[:3] += 0.01 * x[3:]
        flip = rng.random(6) < 0.002
        s = np.where(flip, 1 - s, s)
        d = np.linalg.norm(ANCHORS - x[:2], axis=1) + x[2]
        n = np.where(
            s == 0,
            rng.normal(0, np.sqrt(10.0), 6),
            rng.rayleigh(np.sqrt(2 * 5000 / (4 - np.pi)), 6),
        )
        Y.append(d + n)
        Q_obs.append(np.where(s == 0, rng.beta(4, 1.5, 6), rng.beta(1.5, 4, 6)))
        S.append(s.copy())
    return np.array(Y), np.array(Q_obs), np.array(S), x


@pytest.mark.parametrize(
    "variant,m", [(rbpf.RbpfVariant.Reordered, 16), (rbpf.RbpfVariant.Classical, 2)]
)
def test_rbpf_run_and_step(variant, m):
    Y, Q_obs, S, x = track()
    opt = rbpf.RbpfOptions(variant=variant, num_particles=m, threads=2)
    f = rbpf.Rbpf(MOTION, stack(), SIGHT, QUALITY, X0, P0, opt)
    out = f.run(Y, Q_obs)
    assert out["mean"].shape == (100, 6)
    assert out["cov"].shape == (100, 6, 6)
    assert out["situation_probabilities"].shape == (100, 6, 2)
    np.testing.assert_allclose(out["situation_probabilities"].sum(axis=2), 1.0, atol=1e-9)
    # measured 0.67 m and 6 of 6 anchors (seeded; bit-identical for any thread count); the prior
    # mean alone is 1.12 m off, and a random sight guess gets 5 or 6 right 11% of the time
    assert np.linalg.norm(out["mean"][-1, :2] - x[:2]) < 1.0
    assert (f.sight_estimate() == S[-1]).mean() >= 5 / 6
    assert f.num_particles <= m
    assert f.weights.sum() == pytest.approx(1.0)
    info = f.step(Y[-1], Q_obs[-1])
    assert info.ukf_runs > 0 and info.failures == 0
    assert f.particle_situation(0).shape == (6,)
    with pytest.raises(ValueError, match="o"):
        f.step(Y[-1], Q_obs[-1][:3])


def test_rbpf_threads_give_the_same_result_bit_for_bit():
    # M = 128: the 2-thread filter uses its pool (from 64 parents); the UKF bank's chunks and
    # partial sums do not depend on the threads, so neither do the outputs, to the last bit.
    Y, Q_obs, _, _ = track(steps=60, seed=3)
    out = []
    for threads in (1, 2):
        opt = rbpf.RbpfOptions(
            variant=rbpf.RbpfVariant.Reordered, num_particles=128, threads=threads
        )
        out.append(rbpf.Rbpf(MOTION, stack(), SIGHT, QUALITY, X0, P0, opt).run(Y, Q_obs))
    for key in ("mean", "cov", "situation_probabilities"):
        np.testing.assert_array_equal(out[0][key], out[1][key], err_msg=key)


def test_rbpf_bad_options():
    with pytest.raises(ValueError, match="num_particles"):
        rbpf.Rbpf(MOTION, stack(), SIGHT, QUALITY, X0, P0, rbpf.RbpfOptions(num_particles=0))
    with pytest.raises(ValueError, match="mean"):
        rbpf.Rbpf(MOTION, stack(), SIGHT, QUALITY, np.zeros(4), P0)


def test_particle_filter_and_iukf():
    Y, Q_obs, _, x = track(seed=2)
    pf = rbpf.ParticleFilter(
        MOTION,
        stack(),
        SIGHT,
        QUALITY,
        X0,
        P0,
        rbpf.PfOptions(num_particles=20000, threads=2, seed=1),
    )
    out = pf.run(Y, Q_obs)
    assert np.linalg.norm(out["mean"][-1, :2] - x[:2]) < 15.0
    assert pf.particles.shape == (6, 20000)
    iukf = rbpf.Iukf(MOTION, stack(), SIGHT, QUALITY, X0, P0)
    res = iukf.run(Y, Q_obs)
    assert np.all(np.isfinite(res["mean"]))
    assert iukf.situation_probabilities.shape == (6, 2)
    # the forward filter is the IUKF's own (not a copy); step_quality is step(y, o)
    np.testing.assert_array_equal(iukf.forward.probabilities, iukf.situation_probabilities)
    twin = rbpf.Iukf(MOTION, stack(), SIGHT, QUALITY, X0, P0)
    twin.run(Y, Q_obs)
    r1, r2 = iukf.step(Y[0], Q_obs[0]), twin.step_quality(Y[0], Q_obs[0])
    assert r1.log_likelihood == r2.log_likelihood
    np.testing.assert_array_equal(iukf.mean, twin.mean)
    assert iukf.time == pytest.approx(0.01 * (len(Y) + 1))
    assert iukf.scheme is not None and iukf.measurements.rows == 6
    # a known situation: the plain UKF step
    mean, cov = iukf.belief()
    np.testing.assert_array_equal(mean, iukf.estimate)
    with pytest.raises(ValueError, match=r"^o, sight: expected exactly one"):
        iukf.step(Y[0])
    iukf.step(Y[0], sight=np.zeros(6, dtype=np.int32))
    iukf.set_belief(mean, cov, 0.0)
    np.testing.assert_array_equal(iukf.mean, mean)
    assert iukf.time == 0.0


def test_merge_and_resampling_helpers():
    logw = np.log([0.1, 0.3, 0.2, 0.25, 0.15])
    means = np.array([[0.0, 0.05, 0.5, 0.01, 0.09]])
    new, n = rbpf.merge_greedy([0, 0, 0, 1, 0], means, logw, 0.1)
    assert n == 2
    np.testing.assert_allclose(np.exp(new), [0.0, 0.55, 0.2, 0.25, 0.0], atol=1e-14)
    # the pairs in merge order: particle 1 (heaviest of key 0) absorbs 4, then 0
    new2, n2, pairs = rbpf.merge_greedy([0, 0, 0, 1, 0], means, logw, 0.1, with_pairs=True)
    assert n2 == 2
    np.testing.assert_array_equal(new2, new)
    np.testing.assert_array_equal(pairs, [[1, 4], [1, 0]])
    none = rbpf.merge_greedy([0, 1], np.zeros((1, 2)), np.log([0.5, 0.5]), 1.0, with_pairs=True)
    assert none[1] == 0 and none[2].shape == (0, 2)
    assert rbpf.default_merge_threshold(12.8, 128) == pytest.approx(0.01)
    w = np.array([0.05, 0.4, 0.1, 0.3, 0.15])
    rng = np.random.default_rng(0)
    counts = np.zeros(5)
    for u in rng.random(20000):
        counts += np.bincount(rbpf.systematic_resample(w, 7, max(u, 1e-12)), minlength=5)
    np.testing.assert_allclose(counts / 20000, 7 * w, atol=0.02)
    assert rbpf.situation_count(2, 6) == 64
    with pytest.raises(ValueError, match=r"^num_conditions: expected an integer >= 1, got 0"):
        rbpf.situation_count(0, 3)
    with pytest.raises(ValueError, match=r"^num_anchors: expected an integer >= 0, got -1"):
        rbpf.situation_count(2, -1)
    with pytest.raises(ValueError, match=r"^d_min: expected a finite value >= 0"):
        rbpf.merge_greedy([0, 0], np.array([[0.0, 0.1]]), np.array([0.0, -1.0]), -1.0)
    with pytest.raises(ValueError, match=r"^logw: expected log weights that are finite or -inf"):
        rbpf.merge_greedy([0, 0], np.array([[0.0, 0.1]]), np.array([np.nan, -1.0]), 1.0)
    with pytest.raises(ValueError, match=r"^w: expected finite weights >= 0 summing to 1"):
        rbpf.systematic_resample(np.array([-1.0, 2.0]), 4, 0.5)


def test_pf_simd_lanes_is_a_packet_width():
    # Doubles per SIMD packet of the PF's loops in this build: x86-64 always has SSE2 (2 lanes);
    # a build with -Ccmake.define.NLOSLOC_NATIVE=ON has 4 (AVX, AVX2) or 8 (AVX-512).
    lanes = rbpf.pf_simd_lanes()
    assert lanes in (1, 2, 4, 8)
    if platform.machine().lower() in ("x86_64", "amd64"):
        assert lanes >= 2


def test_gcrb_below_crb():
    r = bounds.gcrb_rtoa(ANCHORS, np.array([100.0, -50.0]), 10.0 * np.eye(6), 10.0)
    assert np.all(np.linalg.eigvalsh(r.position_crb - r.position_gcrb) >= -1e-12)
    assert r.J.shape == (3, 3)
    with pytest.raises(ValueError, match="sigma_tau2"):
        bounds.gcrb_rtoa(ANCHORS, np.zeros(2), np.eye(6), -1.0)


def test_rbpf_augmented_noise_form_matches_ukf_augmented():
    """Classical RBPF, one step, every child kept: with noise_form=Augmented each particle is the
    Table III UKF (filters.UkfAugmented) under its situation, and its weight is prior x quality x
    that UKF's predictive likelihood (eq. 25); the default additive form is a different filter."""
    from nlosloc import filters

    anchors = np.array([[100.0, 0.0], [0.0, 80.0]])
    motion = models.ConstantVelocity2(0.5, 1.0)
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), anchors, 2)
    for b in range(2):
        st.add_toa(b, [noise.Normal(0.0, 2.0), noise.Rayleigh(15.0)])
    T = np.array([[0.8, 0.2], [0.3, 0.7]])
    pi = np.array([0.9, 0.1])  # not stationary for T, so pi T differs from pi
    sight = situation.SightProcess(situation.SightModel.fixed(T, 1, pi), 2)
    quality = situation.QualityModel([noise.Normal(0.8, 0.2), noise.Normal(0.3, 0.2)])
    x0 = np.array([10.0, 20.0, 1.0, 0.0])
    p0 = np.diag([25.0, 25.0, 1.0, 1.0])
    y, o = np.array([91.0, 62.0]), np.array([0.75, 0.4])
    prior = pi @ T  # first step: p(s_1) = pi T (rbpf.hpp)

    def run(form):
        opt = rbpf.RbpfOptions(
            variant=rbpf.RbpfVariant.Classical, num_particles=4, merge=False, noise_form=form
        )
        f = rbpf.Rbpf(motion, st, sight, quality, x0, p0, opt)
        f.step(y, o)
        return f

    f = run(filters.NoiseForm.Augmented)
    assert f.num_particles == 4
    want_logw = []
    for i in range(4):
        s = f.particle_situation(i)
        ref = filters.UkfAugmented(motion, st, x0, p0)
        res = ref.step(y, s)
        np.testing.assert_allclose(f.particle_mean(i), ref.mean, rtol=0, atol=1e-9)
        np.testing.assert_allclose(f.particle_cov(i), ref.cov, rtol=0, atol=1e-9)
        lw = res.log_likelihood
        for b in range(2):
            lw += np.log(prior[s[b]]) + quality.log_likelihood(o[b], int(s[b]))
        want_logw.append(lw)
    want = np.exp(np.array(want_logw) - np.logaddexp.reduce(want_logw))
    np.testing.assert_allclose(f.weights, want, rtol=1e-9)
    add = run(filters.NoiseForm.Additive)
    assert np.max(np.abs(np.sort(add.weights) - np.sort(f.weights))) > 1e-3
    assert rbpf.RbpfOptions().noise_form == filters.NoiseForm.Additive


def test_particle_filters_accessors_and_rejected_steps():
    Y, Q_obs, _, _ = track(steps=5, seed=3)
    opts = rbpf.RbpfOptions(num_particles=8)
    f = rbpf.Rbpf(MOTION, stack(), SIGHT, QUALITY, X0, P0, opts)
    f.run(Y, Q_obs)
    assert (f.step_index, f.num_anchors, f.num_conditions) == (5, 6, 2)
    assert f.options.num_particles == 8 and f.measurements.rows == 6
    assert f.motion.dt == pytest.approx(0.01)
    w = f.weights
    lw = np.array([f.log_weight(i) for i in range(f.num_particles)])
    np.testing.assert_allclose(np.exp(lw), w, rtol=1e-12, atol=0.0)
    mean, cov = f.belief()
    np.testing.assert_array_equal(mean, f.estimate)
    before = f.estimate.copy()
    with pytest.raises(ValueError, match=r"^o: statistic of anchor 2 has zero density"):
        f.step(Y[0], np.r_[Q_obs[0][:2], 1.5, Q_obs[0][3:]])
    with pytest.raises(ValueError, match=r"^o: expected finite statistics, or NaN"):
        f.step(Y[0], np.r_[np.inf, Q_obs[0][1:]])
    np.testing.assert_array_equal(f.estimate, before)
    assert f.step_index == 5
    pf = rbpf.ParticleFilter(
        MOTION, stack(), SIGHT, QUALITY, X0, P0, rbpf.PfOptions(num_particles=500, seed=2)
    )
    pf.run(Y, Q_obs)
    parts = pf.particles.copy()
    bad = Y[0].copy()
    bad[0] = -1e200  # zero likelihood for every particle: rejected, nothing moves
    with pytest.raises(RuntimeError, match="every particle has zero likelihood"):
        pf.step(bad, Q_obs[0])
    np.testing.assert_array_equal(pf.particles, parts)
    assert pf.options.num_particles == 500 and pf.time == pytest.approx(0.05)
    pf.reset(X0, P0)
    assert pf.time == 0.0
    np.testing.assert_allclose(pf.estimate, X0, atol=1.0)


def test_pf_weights_are_each_particles_likelihood():
    """One PF step without resampling from equal weights: each log weight is, up to the
    normaliser, sum_r log p_n(y_r - g_r(x_i) | s_i) over the rows present plus
    sum_b log p(o_b | s_i,b) over every anchor (a missing range does not drop its anchor's
    quality), computed here from the models alone."""
    Y, Q_obs, _, _ = track(steps=1)
    st = stack()
    opt = rbpf.PfOptions(
        num_particles=64, resampling=rbpf.PfResampling.Systematic, ess_threshold=0.0, seed=3
    )
    pf = rbpf.ParticleFilter(MOTION, st, SIGHT, QUALITY, X0, P0, opt)
    y = Y[0].copy()
    y[4] = np.nan
    pf.step(y, Q_obs[0])
    X, S = pf.particles, pf.situations  # (6, M), (B, M) after the step
    hand = np.zeros(X.shape[1])
    for i in range(X.shape[1]):
        g = st.predict(X[:, i], pf.time)
        for r in range(st.rows):
            if not np.isnan(y[r]):
                hand[i] += st.noise(r, int(S[st.row(r).anchor, i])).log_pdf(y[r] - g[r])
        for b in range(S.shape[0]):
            hand[i] += QUALITY.distribution(int(S[b, i])).log_pdf(Q_obs[0][b])
    finite = np.isfinite(hand)
    # some NLOS particles are impossible (a negative Rayleigh noise)
    assert 0 < finite.sum() < hand.size
    top = hand[finite].max()
    hand -= top + np.log(np.exp(hand[finite] - top).sum())
    lw = pf.log_weights
    np.testing.assert_array_equal(np.isfinite(lw), finite)
    np.testing.assert_allclose(lw[finite], hand[finite], rtol=0, atol=1e-9)


@pytest.mark.parametrize("variant", [rbpf.RbpfVariant.Reordered, rbpf.RbpfVariant.Classical])
def test_zero_transition_probabilities_drop_the_impossible_children(variant):
    # NLOS absorbing (T[1, 0] = 0) for anchors 0-2, NLOS throughout the track: a -inf factor once
    # turned the fully enumerated children into NaN (a wrong estimate, or NumericalError).
    # Reference: T[1, 0] = 1e-300, whose LOS children weigh e^-690 at most and change no estimate.
    Y, Q_obs, S, _ = track(steps=30)
    assert (S[:, :3] == 1).all()
    other = situation.SightModel.fixed(np.array([[0.99, 0.01], [0.02, 0.98]]))
    means = []
    for p in (0.0, 1e-300):
        nlos = situation.SightModel.fixed(np.array([[0.7, 0.3], [p, 1.0 - p]]))
        sight = situation.SightProcess([nlos] * 3 + [other] * 3)
        m = 16 if variant == rbpf.RbpfVariant.Reordered else 2
        opt = rbpf.RbpfOptions(variant=variant, num_particles=m)
        means.append(rbpf.Rbpf(MOTION, stack(), sight, QUALITY, X0, P0, opt).run(Y, Q_obs)["mean"])
    assert np.isfinite(means[0]).all()
    np.testing.assert_allclose(means[0], means[1], rtol=0, atol=1e-9)


def _cpu_has_avx2():
    try:
        with open("/proc/cpuinfo") as f:
            return any(line.startswith("flags") and " avx2" in line for line in f)
    except OSError:
        return False


def test_pf_avx2_pass_steps_bit_for_bit_as_the_portable_pass(monkeypatch):
    """A ParticleFilter built with NLOSLOC_NO_AVX2=1 runs the portable pass, one built without
    it the AVX2 build where this x86-64 CPU has AVX2 (and the module is the portable build): the
    same seed and data give the same particles, weights and summaries, bit for bit."""
    Y, Q_obs, _, _ = track(steps=20)
    opt = rbpf.PfOptions(
        num_particles=2001,
        threads=2,
        resampling=rbpf.PfResampling.MergeSelect,
        merge_threshold=3.0,
        seed=4,
    )
    monkeypatch.delenv("NLOSLOC_NO_AVX2", raising=False)
    fast = rbpf.ParticleFilter(MOTION, stack(), SIGHT, QUALITY, X0, P0, opt)
    monkeypatch.setenv("NLOSLOC_NO_AVX2", "1")
    portable = rbpf.ParticleFilter(MOTION, stack(), SIGHT, QUALITY, X0, P0, opt)
    monkeypatch.setenv("NLOSLOC_NO_AVX2", "0")  # "0" counts as unset
    again = rbpf.ParticleFilter(MOTION, stack(), SIGHT, QUALITY, X0, P0, opt)
    expected = (
        platform.machine() in ("x86_64", "AMD64") and rbpf.pf_simd_lanes() == 2 and _cpu_has_avx2()
    )
    assert fast.uses_avx2 is expected and again.uses_avx2 is expected
    assert portable.uses_avx2 is False
    a, b = fast.run(Y, Q_obs), portable.run(Y, Q_obs)
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    np.testing.assert_array_equal(fast.particles, portable.particles)
    np.testing.assert_array_equal(fast.situations, portable.situations)
    np.testing.assert_array_equal(fast.log_weights, portable.log_weights)
