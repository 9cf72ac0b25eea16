"""Every native estimator of the C++ runner from Python: run_monte_carlo's (name, object) entries
with an Iukf, Rbpf or ParticleFilter (nlosloc.rbpf), a QpBiasEkf or BiasAugmentedEkf
(nlosloc.mitigation), or a snapshot baseline (nlosloc.snapshot), each equal bit for bit to the
registered estimator it rebuilds."""

from __future__ import annotations

import numpy as np
import pytest

from nlosloc import mitigation, rbpf, sim, situation, snapshot


def errors(res: dict) -> dict[str, np.ndarray]:
    return {k: v["errors"] for k, v in res["estimators"].items()}


def start(s: sim.Scenario) -> tuple[np.ndarray, np.ndarray]:
    # any valid belief: the runner restarts every estimator from the draw's initial belief
    return np.zeros(s.state_dim), np.eye(s.state_dim)


def h1_rbpf(s: sim.H1) -> rbpf.Rbpf:
    """H1's registered rRBPF-8 (h1.hpp make_h1_rbpf) from its models."""
    o = rbpf.RbpfOptions()
    o.variant = rbpf.RbpfVariant.Reordered
    o.num_particles = s.params.rbpf_particles
    q = situation.QualityModel(s.quality)
    return rbpf.Rbpf(s.motion, s.measurements, s.sight_process, q, *start(s), options=o)


def h1_iukf(s: sim.H1) -> rbpf.Iukf:
    """H1's registered IUKF (h1.hpp make_h1_iukf)."""
    q = situation.QualityModel(s.quality)
    return rbpf.Iukf(s.motion, s.measurements, s.sight_process, q, *start(s))


def test_h1_iukf_rbpf_and_mle_run_natively_as_the_registered_ones() -> None:
    s = sim.H1()
    f = h1_rbpf(s)
    entries = [
        "MLE-LOS",
        "IUKF",
        "rRBPF-8",
        ("my-MLE", snapshot.MleLos(s.measurements)),
        ("my-IUKF", h1_iukf(s)),
        ("my-rRBPF", f),
    ]
    res = sim.run_monte_carlo(s, "default", 3, 5, entries, threads=2, steps=400)
    e = errors(res)
    np.testing.assert_array_equal(e["my-MLE"], e["MLE-LOS"])
    np.testing.assert_array_equal(e["my-IUKF"], e["IUKF"])
    np.testing.assert_array_equal(e["my-rRBPF"], e["rRBPF-8"])
    est = res["estimators"]
    for mine, theirs in [("my-IUKF", "IUKF"), ("my-rRBPF", "rRBPF-8")]:
        np.testing.assert_array_equal(est[mine]["sight_accuracy"], est[theirs]["sight_accuracy"])
    assert "sight_accuracy" not in est["my-MLE"]  # MLE-LOS classifies nothing
    # the filter given is not run: a new one with its set-up was
    assert f.step_index == 0
    assert f.sight_process.num_anchors == 1
    assert f.quality.num_conditions == 2


def test_h2_baselines_and_particle_filters_run_natively_as_the_registered_ones() -> None:
    p = sim.H2Params()
    p.pf_particles = 3000  # the registered PF's 1e6 takes minutes
    s = sim.H2(p)
    q = situation.QualityModel(s.quality)
    urr = snapshot.UrruelaOptions()
    urr.p_nlos = p.mean_nlos / (p.mean_los + p.mean_nlos)
    urr.p_ln = s.urr_switch_probability(0)
    urr.p_nl = s.urr_switch_probability(1)
    urr.nlos_span = s.urr_nlos_span()
    crbpf = rbpf.RbpfOptions()
    crbpf.variant = rbpf.RbpfVariant.Classical
    crbpf.num_particles = 2
    pf = rbpf.PfOptions()
    pf.num_particles = p.pf_particles
    pf.resampling = rbpf.PfResampling.MergeSelect
    pf.seed = 12345  # replaced at every run by a draw from the estimator's own stream
    m, c = start(s)
    entries = [
        "CHEN",
        "CONG",
        "URR",
        "cRBPF-128",
        "PF",
        ("my-CHEN", snapshot.Chen(s.measurements)),
        ("my-CONG", snapshot.Cong(s.measurements)),
        ("my-URR", snapshot.Urruela(s.measurements, urr)),
        ("my-cRBPF", rbpf.Rbpf(s.motion, s.measurements, s.sight_process, q, m, c, crbpf)),
    ]
    res = sim.run_monte_carlo(s, "default", 2, 3, entries, threads=2, steps=60)
    e = errors(res)
    for name in ["CHEN", "CONG", "URR", "cRBPF"]:
        np.testing.assert_array_equal(e["my-" + name], e[name if name != "cRBPF" else "cRBPF-128"])
    # A PF's particles come from its own stream Rng(estimator_seed(seed, name), run): under the
    # registered name it draws what the registered PF draws.
    mine = sim.run_monte_carlo(
        s,
        "default",
        2,
        3,
        [("PF", rbpf.ParticleFilter(s.motion, s.measurements, s.sight_process, q, m, c, pf))],
        threads=2,
        steps=60,
    )
    np.testing.assert_array_equal(errors(mine)["PF"], e["PF"])
    assert np.median(e["PF"][:, 30:]) < 20.0  # and it tracks


def test_k1_mitigation_trackers_run_natively_as_the_registered_ones() -> None:
    s = sim.K1()
    p = s.params
    o = mitigation.QpBiasEkfOptions()
    o.gamma = p.gamma
    o.noise.sigma0 = p.sigma_los
    it = mitigation.BiasAugmentedEkfOptions()
    it.noise.sigma0 = p.sigma_los
    it.bias_prior_std = p.iterated_bias_prior_std
    it.bias_walk_std = p.iterated_bias_walk_std
    it.iterations = p.iterated_iterations
    m, c = np.zeros(4), np.eye(4)
    qp = mitigation.QpBiasEkf(s.motion, p.anchors, m, c, o)
    entries = [
        "proposed",
        "iterated-NLOS-EKF",
        ("my-proposed", qp),
        ("my-iterated", mitigation.BiasAugmentedEkf(s.motion, p.anchors, m, c, it)),
    ]
    res = sim.run_monte_carlo("K1", "2LOS/1NLOS", 4, 7, entries, threads=2, steps=300)
    e = errors(res)
    np.testing.assert_array_equal(e["my-proposed"], e["proposed"])
    np.testing.assert_array_equal(e["my-iterated"], e["iterated-NLOS-EKF"])
    est = res["estimators"]
    np.testing.assert_array_equal(
        est["my-proposed"]["sight_accuracy"], est["proposed"]["sight_accuracy"]
    )
    assert qp.time == 0.0 and np.array_equal(qp.mean, m)  # a copy ran
    # through a factory too (what pickles for montecarlo.run(executor=...))
    made = sim.run_monte_carlo(
        "K1",
        "2LOS/1NLOS",
        4,
        7,
        [("made", lambda sc, k: mitigation.QpBiasEkf(sc.motion, sc.params.anchors, m, c, o))],
        threads=2,
        steps=300,
    )
    np.testing.assert_array_equal(errors(made)["made"], e["proposed"])


def test_a_factory_that_returns_an_rbpf_runs_it_natively() -> None:
    s = sim.H1()
    res = sim.run_monte_carlo(
        s, "default", 2, 5, ["rRBPF-8", ("made", lambda sc, k: h1_rbpf(sc))], threads=2, steps=300
    )
    e = errors(res)
    np.testing.assert_array_equal(e["made"], e["rRBPF-8"])


def test_native_objects_that_do_not_fit_are_refused_naming_them() -> None:
    h1, h2, k1 = sim.H1(), sim.H2(), sim.K1()
    run = sim.run_monte_carlo
    with pytest.raises(
        ValueError, match="the Iukf of 'x' has a state of 4 components; scenario H2 has 6"
    ):
        run(h2, "default", 1, 1, [("x", h1_iukf(h1))], steps=10)
    with pytest.raises(
        ValueError, match="the Rbpf of 'x' has a state of 4 components; scenario H2 has 6"
    ):
        run(h2, "default", 1, 1, [("x", h1_rbpf(h1))], steps=10)
    with pytest.raises(
        ValueError, match="the MleLos of 'x' has 4 measurement rows; scenario K1 has 3"
    ):
        run(k1, "3LOS/0NLOS", 1, 1, [("x", snapshot.MleLos(h1.measurements))], steps=10)
    qp = mitigation.QpBiasEkf(k1.motion, k1.params.anchors, np.zeros(4), np.eye(4))
    with pytest.raises(
        ValueError, match="the QpBiasEkf of 'x' has 3 measurement rows; scenario H1 has 4"
    ):
        run(h1, "default", 1, 1, [("x", qp)], steps=10)
    with pytest.raises(
        ValueError, match="the QpBiasEkf of 'x' has a state of 4 components; scenario H2"
    ):
        run(h2, "default", 1, 1, [("x", qp)], steps=10)
    with pytest.raises(
        TypeError,
        match="'x' is an object of type Rbpf; a sight policy goes with an Ekf, Ukf or UkfAugmented",
    ):
        run(h1, "default", 1, 1, [("x", h1_rbpf(h1), "oracle")], steps=10)
    with pytest.raises(
        TypeError, match=r"estimators\[0\]: expected .* rbpf.Iukf, Rbpf or ParticleFilter"
    ):
        run(h1, "default", 1, 1, [("x", situation.QualityModel(h1.quality))], steps=10)
