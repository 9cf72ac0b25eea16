"""nlosloc.situation: sight chains (Huerta eqs. 10, 15-18; Grisales eq. 16), quality
likelihoods and the forward filter (eqs. 36-38) against hand values."""

import math

import numpy as np
import pytest

from nlosloc import core, noise, situation


def test_speed_transitions_hand_values():
    t15 = situation.speed_transition_single(10.0, 0.01, 30.0, 5.0)
    np.testing.assert_allclose(t15, [[30 / 30.1, 0.1 / 30.1], [0.1 / 5.1, 5 / 5.1]], rtol=1e-14)
    rho = 1.0 / (1.0 - (0.1 / 30.1) * (0.1 / 5.1))
    t17 = situation.speed_transition_multiple(10.0, 0.01, 30.0, 5.0)
    assert t17[0, 1] == pytest.approx(0.1 / 30.1 * 5 / 5.1 * rho, rel=1e-14)
    np.testing.assert_allclose(t17.sum(axis=1), [1.0, 1.0], atol=1e-15)
    t18 = situation.speed_transition_memoryless(30.0, 5.0)
    assert t18[0, 1] == pytest.approx(5 / 35)
    assert situation.transversal_speed(
        np.array([100.0, 0.0]), np.array([3.0, 4.0]), np.zeros(2)
    ) == pytest.approx(4.0)
    with pytest.raises(ValueError, match=r"^w: expected a finite value >= 0, got -1"):
        situation.speed_transition_single(-1.0, 0.01, 30.0, 5.0)
    anchors = np.array([[0.0, 0.0], [100.0, 100.0]])
    np.testing.assert_allclose(
        situation.transversal_speeds(np.array([100.0, 0.0]), np.array([3.0, 4.0]), anchors),
        [4.0, 3.0],
        rtol=1e-14,
    )
    with pytest.raises(ValueError, match=r"^anchors: expected shape \(-1, 2\), got \(2, 3\)"):
        situation.transversal_speeds(np.zeros(2), np.zeros(2), np.zeros((2, 3)))


def test_sight_model_and_process():
    q = np.array([[0.97, 0.01, 0.02], [0.01, 0.97, 0.02], [0.025, 0.025, 0.95]])
    m = situation.SightModel.fixed(q, 150)
    assert m.num_conditions == 3
    np.testing.assert_array_equal(m.transition(1), np.eye(3))
    np.testing.assert_allclose(m.transition(150), q)
    assert m.initial.sum() == pytest.approx(1.0)
    with pytest.raises(ValueError, match="k_sight"):
        situation.SightModel.fixed(q, 0)
    with pytest.raises(ValueError, match="transition"):
        situation.SightModel.fixed(np.array([[0.5, 0.4], [0.1, 0.9]]))
    sp = situation.SightModel.speed_dependent(30.0, 5.0, 0.01, situation.SpeedModel.Multiple)
    assert sp.is_speed_dependent
    assert (sp.mean_los, sp.mean_nlos, sp.dt, sp.form) == (
        30.0,
        5.0,
        0.01,
        situation.SpeedModel.Multiple,
    )
    # closed-form switch probability = off-diagonal of eq. (17)
    assert situation.speed_switch_probability(sp, 0, 10.0) == pytest.approx(
        sp.transition(1, 10.0)[0, 1]
    )
    assert situation.speed_switch_probability(sp, 1, 10.0) == pytest.approx(
        sp.transition(1, 10.0)[1, 0]
    )
    with pytest.raises(ValueError, match=r"^model: expected a speed-dependent chain"):
        situation.speed_switch_probability(m, 0, 1.0)
    with pytest.raises(ValueError, match=r"^current: expected 0 \(LOS\) or 1 \(NLOS\), got 2"):
        situation.speed_switch_probability(sp, 2, 1.0)
    # a reducible chain (T = I) has no unique stationary vector: the uniform prior
    np.testing.assert_allclose(situation.SightModel.fixed(np.eye(2)).initial, [0.5, 0.5])
    with pytest.raises(ValueError, match=r"^num_anchors: expected an integer >= 1, got 0"):
        situation.SightProcess(sp, 0)
    proc = situation.SightProcess(sp, 4)
    rng = core.Rng(3)
    s0 = proc.sample_initial(rng)
    s1 = proc.sample_next(s0, 1, np.full(4, 10.0), rng)
    assert s1.shape == (4,)
    assert proc.log_transition(s0, s0, 1, np.zeros(4)) == pytest.approx(0.0)


def test_forward_filter_hand_calculation():
    t = np.array([[0.9, 0.1], [0.2, 0.8]])
    proc = situation.SightProcess(situation.SightModel.fixed(t, 1, np.array([0.5, 0.5])), 1)
    qm = situation.QualityModel([noise.Normal(1.0, 0.5), noise.Normal(0.0, 0.5)])
    f = situation.ForwardFilter(proc, qm)
    f.step(np.array([0.8]))
    l0, l1 = math.exp(-0.5 * 0.04 / 0.25), math.exp(-0.5 * 0.64 / 0.25)
    g0 = 0.55 * l0 / (0.55 * l0 + 0.45 * l1)
    assert f.predicted[0, 0] == pytest.approx(0.55)
    assert f.probabilities[0, 0] == pytest.approx(g0, abs=1e-14)
    f.step(np.array([np.nan]))
    assert f.probabilities[0, 0] == pytest.approx(0.9 * g0 + 0.2 * (1 - g0), abs=1e-14)
    with pytest.raises(ValueError, match=r"^o: expected shape \(1, 1\), got \(2, 1\)"):
        f.update(np.zeros(2))
    assert f.last_log_evidence == pytest.approx(0.0)  # the missing statistic carried no evidence
    assert f.process.num_anchors == 1
    assert f.quality.num_conditions == 2
    # save / restore undoes steps exactly; a snapshot of another size is refused
    snap = f.save()
    before = f.probabilities.copy()
    f.step(np.array([0.1]))
    assert f.step_index == snap.k + 1
    f.restore(snap)
    np.testing.assert_array_equal(f.probabilities, before)
    assert f.step_index == snap.k
    other = situation.ForwardFilter(situation.SightProcess(proc.model(0), 2), qm)
    with pytest.raises(ValueError, match="snapshot.gamma"):
        f.restore(other.save())


def test_forward_filter_far_statistic_under_the_only_predicted_condition():
    # eqs. (37)-(38) were normalised by the largest log p(o | k) alone: the sum underflowed to 0 and
    # the statistic was refused as impossible. K_sight = 10 keeps T = I between change epochs.
    q = situation.QualityModel([noise.Normal(0.0, 1.0), noise.Normal(50.0, 1.0)])
    chain = situation.SightModel.fixed(np.array([[0.9, 0.1], [0.1, 0.9]]), 10)
    f = situation.ForwardFilter(situation.SightProcess(chain, 1), q)
    f.step(np.array([50.0]))
    assert f.probabilities[0, 1] == 1.0
    assert f.step(np.array([5.0])) == pytest.approx(noise.Normal(50.0, 1.0).log_pdf(5.0), rel=1e-14)
    assert f.probabilities[0, 1] == 1.0


def test_quality_model_empirical():
    rng = np.random.default_rng(1)
    qm = situation.QualityModel([noise.Empirical(rng.beta(4, 1.5, 400)), noise.Beta(1.5, 4.0)])
    table = qm.log_likelihood_table(np.array([0.9, 0.1, np.nan]))
    assert table.shape == (3, 2)
    assert table[0, 0] > table[0, 1] and table[1, 1] > table[1, 0]
    np.testing.assert_array_equal(table[2], [0.0, 0.0])


def test_forward_filter_rejected_calls_change_nothing():
    sp = situation.SightModel.speed_dependent(30.0, 5.0, 0.1)
    qm = situation.QualityModel([noise.Beta(4.0, 1.5), noise.Beta(1.5, 4.0)])
    f = situation.ForwardFilter(situation.SightProcess(sp, 2), qm)
    f.step(np.array([0.9, 0.2]), np.array([3.0, 1.0]))
    before = (f.probabilities.copy(), f.predicted.copy(), f.step_index, f.last_log_evidence)

    def same():
        np.testing.assert_array_equal(f.probabilities, before[0])
        np.testing.assert_array_equal(f.predicted, before[1])
        assert (f.step_index, f.last_log_evidence) == before[2:]

    with pytest.raises(ValueError, match=r"^o: expected shape \(2, 1\), got \(1, 1\)"):
        f.step(np.zeros(1), np.array([3.0, 1.0]))
    same()
    with pytest.raises(ValueError, match=r"^speeds: expected finite values >= 0, got -1"):
        f.predict(np.array([3.0, -1.0]))
    same()
    with pytest.raises(ValueError, match=r"^o: statistic of anchor 1 has zero density"):
        f.step(np.array([0.9, 7.0]), np.array([3.0, 1.0]))
    same()
    with pytest.raises(ValueError, match=r"^o: statistic of anchor 1 has zero density"):
        f.update(np.array([0.1, 7.0]))  # anchor 0 is not updated either
    same()
    with pytest.raises(ValueError, match=r"^o: expected finite statistics, or NaN"):
        f.update(np.array([0.1, np.inf]))
    same()
    # set_probabilities is the prior of the next update
    f.set_probabilities(np.array([[0.0, 1.0], [0.0, 1.0]]))
    f.update(np.array([0.8, 0.8]))
    np.testing.assert_array_equal(f.probabilities, [[0.0, 1.0], [0.0, 1.0]])


def test_quality_model_sample_one_condition():
    qm = situation.QualityModel([noise.Normal(1.0, 0.5), noise.Beta(1.5, 4.0)])
    for z in (0, 1):
        assert qm.sample(z, core.Rng(5, 2)) == qm.distribution(z).sample(core.Rng(5, 2))
    # the vector form draws anchor by anchor from one generator
    r, r2 = core.Rng(8), core.Rng(8)
    o = qm.sample(np.array([1, 0, 1]), r)
    np.testing.assert_array_equal(o, [qm.sample(1, r2), qm.sample(0, r2), qm.sample(1, r2)])
    with pytest.raises(ValueError, match=r"^z: expected a condition in \[0, N_z\), got 2"):
        qm.sample(2, core.Rng())
    with pytest.raises(ValueError, match=r"^z: expected a condition in \[0, N_z\), got -1"):
        qm.sample(-1, core.Rng())


def test_quality_model_vector_forms():
    qm = situation.QualityModel([noise.Normal(1.0, 0.5), noise.Normal(0.0, 0.5)])
    l0 = -0.5 * 0.04 / 0.25 - math.log(0.5 * math.sqrt(2 * math.pi))
    l1 = -0.5 * 0.64 / 0.25 - math.log(0.5 * math.sqrt(2 * math.pi))
    np.testing.assert_allclose(qm.log_likelihoods(0.8), [l0, l1], rtol=1e-14)
    assert qm.log_likelihood(np.array([0.8, 0.8, np.nan]), np.array([0, 1, 1])) == pytest.approx(
        l0 + l1
    )


def test_arguments_checked_that_the_chain_does_not_read():
    """Found by an API check: these were ignored, so a wrong value passed silently."""
    rng = core.Rng(1)
    # eq. (18) does not depend on w, but w is checked as for eqs. (15) and (17)
    for form in (
        situation.SpeedModel.Single,
        situation.SpeedModel.Multiple,
        situation.SpeedModel.Memoryless,
    ):
        m = situation.SightModel.speed_dependent(50.0, 10.0, 1.0, form)
        for w in (math.nan, -5.0, math.inf):
            with pytest.raises(ValueError, match=r"^w: expected a finite value >= 0"):
                m.transition(1, w)
            with pytest.raises(ValueError, match=r"^w: expected a finite value >= 0"):
                m.sample_next(0, 1, w, rng)
    # a fixed chain does not read speeds: they may be left out, but are checked when given
    p = situation.SightProcess(situation.SightModel.fixed(np.array([[0.9, 0.1], [0.2, 0.8]])), 3)
    q = situation.QualityModel([noise.Beta(4, 1.5), noise.Beta(1.5, 4)])
    f = situation.ForwardFilter(p, q)
    s0 = np.zeros(3, dtype=int)
    o = np.array([0.5, 0.5, 0.5])
    for bad, msg in (
        (np.array([np.nan, -1.0]), r"^speeds: expected shape \(3, 1\), got \(2, 1\)$"),
        (
            np.array([1.0, np.nan, 1.0]),
            r"^speeds: expected finite values >= 0, got nan at anchor 1$",
        ),
    ):
        with pytest.raises(ValueError, match=msg):
            f.predict(bad)
        with pytest.raises(ValueError, match=msg):
            f.step(o, bad)
        with pytest.raises(
            ValueError, match=msg.replace("finite values", "finite transversal speeds")
        ):
            p.sample_next(s0, 1, bad, rng)
        with pytest.raises(
            ValueError, match=msg.replace("finite values", "finite transversal speeds")
        ):
            p.log_transition(s0, s0, 1, bad)
    assert f.step_index == 0
    f.step(o)
    assert f.step_index == 1
    f.predict(np.ones(3))
    assert f.step_index == 2
    assert p.log_transition(s0, s0, 1, np.array([])) == pytest.approx(3 * math.log(0.9))
    # the vector forms of the quality model name s and the anchor, not the inner z
    with pytest.raises(
        ValueError, match=r"^s: expected conditions in \[0, N_z = 2\), got 2 at anchor 1$"
    ):
        q.log_likelihood(np.array([0.5, 0.5]), np.array([0, 2]))
    with pytest.raises(
        ValueError, match=r"^s: expected conditions in \[0, N_z = 2\), got 3 at anchor 1$"
    ):
        q.sample(np.array([0, 3]), rng)
