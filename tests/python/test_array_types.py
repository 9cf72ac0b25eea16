"""Float vector and matrix arguments convert strictly: a bool, complex or str array (or a list
numpy reads as one) is refused with a ValueError naming the argument, where pybind11's Eigen caster
cast it to float64 (True as 1.0, the imaginary part dropped with only a numpy warning); a matrix
argument needs 2 dimensions; the object is unchanged after a refused call; lists and integer arrays
still work."""

import pickle
import re

import numpy as np
import pytest

from nlosloc import bounds, core, filters, mitigation, models, noise, rbpf, sim, situation
from test_filters_api import MOTION, P0, X0, stack
from test_rbpf import MOTION as MOTION6
from test_rbpf import P0 as P06
from test_rbpf import QUALITY, SIGHT, track
from test_rbpf import X0 as X06
from test_rbpf import stack as stack6

ANCHORS = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])
BAD_KINDS = [
    (lambda a: np.asarray(a) + 0j, "complex"),
    (lambda a: np.asarray(a) != 0, "bool"),
    (lambda a: np.asarray(a).astype(str), "str"),
]


def refused(name: str, kind: str) -> str:
    return "^" + re.escape(f"{name}: expected real values, got a {kind} array") + "$"


def two_d(name: str, ndim: int) -> str:
    return "^" + re.escape(f"{name}: expected a 2-D float array, got {ndim} dimensions") + "$"


def test_core_functions() -> None:
    cases = [
        ("cov", lambda v: core.sigma_points(X0, v, core.SigmaScheme()), P0),
        ("mean", lambda v: core.sigma_points(v, P0, core.SigmaScheme()), X0),
        ("A", lambda v: core.is_spd(v), P0),
        ("A", lambda v: core.robust_cholesky(v), P0),
        ("v", lambda v: core.log_sum_exp(v), np.array([0.0, 1.0])),
        ("v", lambda v: core.log_normalize(v), np.array([0.0, 1.0])),
        ("x", lambda v: core.gaussian_log_pdf_chol(np.eye(2), v), np.array([0.5, 1.0])),
    ]
    for name, call, good in cases:
        for make, kind in BAD_KINDS:
            with pytest.raises(ValueError, match=refused(name, kind)):
                call(make(good))
        call(good.tolist())  # nested lists of floats still work
        call(good.astype(np.int64) if good.ndim == 2 else good)
    # numpy reads a list of bools as a bool array: refused the same way
    with pytest.raises(ValueError, match=refused("v", "bool")):
        core.log_sum_exp([True, False])
    # pybind11 read a 1-D array as a column matrix
    with pytest.raises(ValueError, match=two_d("A", 1)):
        core.is_spd(np.ones(1))
    with pytest.raises(ValueError, match=two_d("A", 3)):
        core.is_spd(np.ones((1, 1, 1)))
    with pytest.raises(ValueError, match=r"^A: expected a 2-D float array, got None$"):
        core.is_spd(None)


def test_a_filter_is_unchanged_after_a_refused_array() -> None:
    f = filters.Ukf(MOTION, stack(), X0, P0)
    f.step(np.array([1420.0, 7650.0, 6700.0]))
    before = pickle.dumps(f)
    for make, kind in BAD_KINDS:
        with pytest.raises(ValueError, match=refused("cov", kind)):
            f.set_belief(X0, make(P0))
        with pytest.raises(ValueError, match=refused("Y", kind)):
            f.run(make(np.ones((2, 3))))
    with pytest.raises(ValueError, match=two_d("cov", 1)):
        f.set_belief(X0, np.diag(P0))
    assert pickle.dumps(f) == before
    # constructors: every array argument is named
    for make, kind in BAD_KINDS:
        with pytest.raises(ValueError, match=refused("cov", kind)):
            filters.Ekf(MOTION, stack(), X0, make(P0))
        with pytest.raises(ValueError, match=refused("H", kind)):
            filters.Kf(MOTION, make(np.eye(2, 4)), np.eye(2), X0, P0)
        with pytest.raises(ValueError, match=refused("R", kind)):
            filters.Kf(MOTION, np.eye(2, 4), make(np.eye(2)), X0, P0)


def test_particle_filters_and_their_snapshots() -> None:
    Y, Q, _, _ = track(steps=2)
    f = rbpf.Rbpf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06, rbpf.RbpfOptions(num_particles=4))
    f.step(Y[0], Q[0])
    before = pickle.dumps(f)
    for make, kind in BAD_KINDS:
        with pytest.raises(ValueError, match=refused("O", kind)):
            f.run(Y, make(Q))
        with pytest.raises(ValueError, match=refused("cov", kind)):
            f.reset(X06, make(P06))
    assert pickle.dumps(f) == before
    snap = f.save()
    args = dict(
        situations=snap.situations,
        means=snap.means,
        covs=snap.covs,
        log_weights=snap.log_weights,
        situation_probabilities=snap.situation_probabilities,
        estimate=snap.estimate,
        covariance=snap.covariance,
        time=snap.time,
        step=snap.step,
    )
    g = rbpf.Rbpf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06, rbpf.RbpfOptions(num_particles=4))
    g.restore(rbpf.RbpfSnapshot(**args))  # the fields as save() gives them
    g.restore(rbpf.RbpfSnapshot(**{**args, "covs": np.array(snap.covs)}))  # one (P, n, n) array
    covs = list(snap.covs)
    covs[1] = covs[1] + 0j
    with pytest.raises(ValueError, match=refused("covs[1]", "complex")):
        rbpf.RbpfSnapshot(**{**args, "covs": covs})
    with pytest.raises(ValueError, match=refused("covs[0]", "complex")):
        rbpf.RbpfSnapshot(**{**args, "covs": np.array(snap.covs) + 0j})
    seq = "covs: expected a sequence of 2-D float arrays or one 3-D array, got float"
    with pytest.raises(ValueError, match="^" + re.escape(seq) + "$"):
        rbpf.RbpfSnapshot(**{**args, "covs": 3.0})
    # condition indices were truncated (0.5 -> 0) by the integer matrix caster
    half = snap.situations.astype(float)
    half[0, 0] = 0.5
    with pytest.raises(
        ValueError, match=r"^situations: expected integers, got 0\.500000 at \(0, 0\)$"
    ):
        rbpf.RbpfSnapshot(**{**args, "situations": half})
    with pytest.raises(ValueError, match=r"^situations: expected a 2-D integer array$"):
        rbpf.RbpfSnapshot(**{**args, "situations": snap.situations[0]})
    with pytest.raises(ValueError, match=refused("means", "bool")):
        rbpf.RbpfSnapshot(**{**args, "means": snap.means != 0})


def test_situation_models_and_processes() -> None:
    T = np.array([[0.9, 0.1], [0.2, 0.8]])
    for make, kind in BAD_KINDS:
        with pytest.raises(ValueError, match=refused("transition", kind)):
            situation.SightModel.fixed(make(T))
        with pytest.raises(ValueError, match=refused("initial", kind)):
            situation.SightModel.fixed(T, 1, make([0.5, 0.5]))
        with pytest.raises(ValueError, match=refused("speeds", kind)):
            SIGHT.log_transition(np.zeros(6, int), np.zeros(6, int), 1, make(np.ones(6)))
    assert situation.SightModel.fixed(T.tolist(), 1, [0.5, 0.5]).initial.tolist() == [0.5, 0.5]
    # condition vectors: integers only (the caster truncated 0.5 to 0, and took True as 1)
    s0 = np.zeros(6, int)
    with pytest.raises(ValueError, match=r"^from: expected integers, got 0\.500000 at entry 0$"):
        SIGHT.log_transition(np.r_[0.5, np.zeros(5)], s0, 1, np.ones(6))
    with pytest.raises(ValueError, match=refused("to", "bool")):
        SIGHT.log_transition(s0, s0 == 0, 1, np.ones(6))
    with pytest.raises(ValueError, match=refused("current", "complex")):
        SIGHT.sample_next(s0 + 0j, 1, np.ones(6), core.Rng(1))
    assert SIGHT.log_transition(s0, s0.astype(float), 1, np.ones(6)) == SIGHT.log_transition(
        s0, s0, 1, np.ones(6)
    )
    fwd = situation.ForwardFilter(SIGHT, QUALITY)
    before = pickle.dumps(fwd)
    for make, kind in BAD_KINDS:
        with pytest.raises(ValueError, match=refused("gamma", kind)):
            fwd.set_probabilities(make(np.full((6, 2), 0.5)))
        with pytest.raises(ValueError, match=refused("speeds", kind)):
            fwd.predict(make(np.ones(6)))
        with pytest.raises(ValueError, match=refused("o", kind)):
            fwd.step(make(np.full(6, 0.5)), np.ones(6))
    assert pickle.dumps(fwd) == before


def test_models_bounds_and_mitigation() -> None:
    layout = models.ConstantVelocity2.layout()
    for make, kind in BAD_KINDS:
        with pytest.raises(ValueError, match=refused("anchors", kind)):
            models.MeasurementStack(layout, make(ANCHORS), 2)
        with pytest.raises(ValueError, match=refused("h", kind)):
            models.MeasurementStack(layout, ANCHORS, 2).add_linear(make([1.0, 0, 0, 0]), -1, [])
        with pytest.raises(ValueError, match=refused("Q", kind)):
            bounds.gcrb_rtoa(ANCHORS, np.array([3.0, 4.0]), make(np.eye(3)), 1.0)
        with pytest.raises(ValueError, match=refused("anchors", kind)):
            bounds.gcrb_rtoa(make(ANCHORS), np.array([3.0, 4.0]), np.eye(3), 1.0)
        with pytest.raises(ValueError, match=refused("position", kind)):
            bounds.gcrb_rtoa(ANCHORS, make([3.0, 4.0]), np.eye(3), 1.0)
        with pytest.raises(ValueError, match=refused("D", kind)):
            mitigation.BiasEstimator(ANCHORS).estimate_from_innovation(
                np.full(3, 5.0), np.zeros(3), make(np.eye(3))
            )
        with pytest.raises(ValueError, match=refused("cov", kind)):
            mitigation.QpBiasEkf(MOTION, ANCHORS, X0, make(P0))
    r = bounds.gcrb_rtoa(ANCHORS.tolist(), [3.0, 4.0], np.eye(3, dtype=int), 1.0)
    np.testing.assert_allclose(
        r.position_gcrb,
        bounds.gcrb_rtoa(ANCHORS, np.array([3.0, 4.0]), np.eye(3), 1.0).position_gcrb,
    )
    # fixed-size fields of the scenario parameters
    p = sim.H1Params()
    start = p.start.copy()
    with pytest.raises(ValueError, match=refused("H1Params.start", "complex")):
        p.start = start + 1j
    np.testing.assert_array_equal(p.start, start)


def test_a_python_estimator_returning_complex_values_is_refused() -> None:
    class Complex:
        def reset(self, draw, rng):
            pass

        def step(self, k, y, o):
            return np.array([1.0 + 0j, 2.0])

    with pytest.raises(ValueError, match=refused("estimators: step() of 'c'", "complex")):
        sim.run_monte_carlo(
            "K1", "3LOS/0NLOS", 1, 1, [("c", lambda s, c: Complex())], threads=1, steps=105
        )


def test_overloads_still_dispatch_by_the_value() -> None:
    # A strict argument takes any object, so that its errors name it; in pybind11's first (exact)
    # pass over an overloaded function's forms it takes only a value that converts, so that a later
    # form gets the rest: QualityModel.log_likelihood's vector form took numpy.float32(0.5), meant
    # for the scalar form, and raised "o: expected a 1-D float array, got 0 dimensions".
    q = situation.QualityModel([noise.Beta(4.0, 1.5), noise.Beta(1.5, 4.0)])
    ref = q.log_likelihood(0.5, 1)
    for o in (np.float32(0.5), np.float64(0.5), 0.5, np.array(0.5)):
        assert q.log_likelihood(o, 1) == pytest.approx(ref, rel=1e-7)
    assert q.log_likelihood(np.array([0.5, 0.5]), [1, 0]) == pytest.approx(
        ref + q.log_likelihood(0.5, 0)
    )
    with pytest.raises(ValueError, match=refused("o", "complex")):
        q.log_likelihood(np.array([0.5, 0.5]) + 0j, [1, 0])
    # run_k2_study's first form (runs, seed, ...) must not take the K2 of the second as `runs`
    r = sim.run_k2_study(sim.K2(), 1, 5, 105, ["EKF"])
    assert r.runs == 1
    with pytest.raises(TypeError, match=r"^runs: expected an integer, got True \(bool\)$"):
        sim.run_k2_study(sim.K2(), True, 5, 105, ["EKF"])
