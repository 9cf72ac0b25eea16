"""Input checks across the Python API: batch runs check every row before the first step, integer
arguments reject fractions, state layouts and row indices are checked, infinite measurements are
errors (NaN is missing) everywhere, getters return copies, and the C++ accessors have Python
twins."""

import pickle

import numpy as np
import pytest

from nlosloc import (
    core,
    filters,
    mitigation,
    models,
    montecarlo,
    noise,
    rbpf,
    sim,
    situation,
    snapshot,
)
from test_filters_api import MOTION, P0, X0, stack
from test_rbpf import MOTION as MOTION6
from test_rbpf import P0 as P06
from test_rbpf import QUALITY, SIGHT, track
from test_rbpf import X0 as X06
from test_rbpf import stack as stack6
from test_snapshot import HEX, rtoa_stack

Y3 = np.array([1420.0, 7650.0, 6700.0])
INF_ROW = r"expected finite values, or NaN for a missing row; got inf at row"


def state(f, names):
    out = []
    for n in names:
        v = getattr(f, n)
        out.append(np.array(v() if callable(v) else v, copy=True))
    return out


def assert_same(a, b):
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("cls", [filters.Ekf, filters.Ukf, filters.UkfAugmented])
def test_run_with_no_rows(cls):
    f = cls(MOTION, stack(), X0, P0)
    for sight in (None, np.zeros(3, dtype=int), np.zeros((0, 3), dtype=int)):
        out = f.run(np.zeros((0, 3)), sight=sight)
        assert out["mean"].shape == (0, 4)
        assert out["cov"].shape == (0, 4, 4)
    assert f.time == 0.0


def test_sight_arguments_must_be_integers():
    f = filters.Ukf(MOTION, stack(), X0, P0)
    g = filters.Ukf(MOTION, stack(), X0, P0)
    with pytest.raises(ValueError, match=r"^sight: expected integers, got 0\.500000 at entry 0$"):
        f.step(Y3, sight=np.array([0.5, 1.0, 0.0]))
    assert f.time == 0.0
    # integral floats are integers
    f.step(Y3, sight=np.array([0.0, 1.0, 0.0]))
    g.step(Y3, sight=np.array([0, 1, 0]))
    np.testing.assert_array_equal(f.mean, g.mean)
    with pytest.raises(ValueError, match=r"^sight: expected integers, got 1\.500000 at \(1, 1\)$"):
        f.run(np.tile(Y3, (2, 1)), sight=np.array([[0, 0, 0], [0, 1.5, 0]]))
    st = stack()
    with pytest.raises(ValueError, match="^sight: expected integers"):
        st.noise_moments(X0, np.array([0.0, 0.2, 0.0]))
    with pytest.raises(ValueError, match="^sight: expected a 1-D integer array"):
        st.noise_moments(X0, np.zeros((1, 3)))
    q = situation.QualityModel([noise.Beta(4.0, 1.5), noise.Beta(1.5, 4.0)])
    with pytest.raises(ValueError, match="^s: expected integers"):
        q.log_likelihood(np.array([0.5, 0.5]), np.array([0.0, 0.9]))
    # complex labels were cast to their real part (numpy only warned)
    with pytest.raises(ValueError, match="^sight: expected real values, got a complex array$"):
        f.step(Y3, sight=np.array([0, 1j, 0]))
    assert f.time == pytest.approx(MOTION.dt)


def test_layout_indices_are_checked_and_the_layout_is_a_copy():
    layout = models.ConstantVelocity2.layout()
    layout.clock_bias = 7
    with pytest.raises(ValueError, match=r"^layout: clock_bias = 7 does not fit a state of 4"):
        models.MeasurementStack(layout, np.zeros((3, 2)), 2)
    layout = models.ConstantVelocity2.layout()
    layout.velocity = 3
    with pytest.raises(ValueError, match=r"^layout: velocity = 3 does not fit"):
        models.MeasurementStack(layout, np.zeros((3, 2)), 2)
    st = stack()
    st.layout.clock_bias = 2  # changes a copy, not the stack
    assert st.layout.clock_bias == -1


def test_row_queries_check_the_index():
    st = stack()
    with pytest.raises(IndexError, match=r"^i: expected a row index in \[0, 3\), got 10$"):
        st.row(10)
    with pytest.raises(IndexError, match=r"^i: expected a row index in \[0, 3\), got -1$"):
        st.is_angle(-1)
    msg = r"^condition: expected a sight condition in \[0, 2\), got 5$"
    with pytest.raises(IndexError, match=msg):
        st.noise(0, 5)
    assert not st.is_angle(2)


def particle_filters():
    yield rbpf.Rbpf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06, rbpf.RbpfOptions(num_particles=8))
    yield rbpf.ParticleFilter(
        MOTION6, stack6(), SIGHT, QUALITY, X06, P06, rbpf.PfOptions(num_particles=64, seed=1)
    )
    yield rbpf.Iukf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06)


@pytest.mark.parametrize("f", list(particle_filters()), ids=["Rbpf", "ParticleFilter", "Iukf"])
def test_quality_runs_check_every_row_before_the_first_step(f):
    Y, Q, _, _ = track(steps=6)
    names = ("estimate", "covariance", "situation_probabilities", "time")
    before = state(f, names)
    bad = Y.copy()
    bad[2, 0] = np.inf
    with pytest.raises(ValueError, match=rf"^step 2: y: {INF_ROW} 0$"):
        f.run(bad, Q)
    assert_same(before, state(f, names))
    bad = Q.copy()
    bad[1, 3] = -np.inf
    with pytest.raises(ValueError, match=r"^step 1: o: .*got inf at anchor 3$"):
        f.run(Y, bad)
    bad = Q.copy()
    bad[4, 0] = 2.0  # outside both Beta supports
    msg = "^step 4: o: statistic of anchor 0 has zero density under every condition$"
    with pytest.raises(ValueError, match=msg):
        f.run(Y, bad)
    msg = r"^Y, O: expected the same number of steps \(rows\), got 6 and 5$"
    with pytest.raises(ValueError, match=msg):
        f.run(Y, Q[:5])
    assert_same(before, state(f, names))
    with pytest.raises(ValueError, match=rf"^y: {INF_ROW} 0$"):
        f.check_inputs(np.r_[np.inf, Y[0, 1:]], Q[0])
    f.check_inputs(Y[0], Q[0])  # good inputs: nothing raised, nothing changed
    assert_same(before, state(f, names))
    out = f.run(Y, Q)
    assert out["mean"].shape == (6, 6)


def test_numerical_error_in_a_run_names_the_step():
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), np.zeros((3, 2)), 1)
    for b in range(3):
        st.add_toa(b, [noise.Normal(0.0, 50.0)])
    # A belief so far out that S overflows at the second update.
    f = filters.Ekf(MOTION, st, np.array([8e153, 8e153, 1e154, 1e154]), np.eye(4))
    Y = np.tile([1.2e154, np.nan, np.nan], (4, 1))
    msg = r"^step 1 \(the filter holds step 0\): Ekf.update"
    with pytest.raises(core.NumericalError, match=msg):
        f.run(Y)
    assert f.time == pytest.approx(MOTION.dt)


ANCHORS = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])
EXACT = np.array([5.0, np.hypot(7.0, 4.0), np.hypot(3.0, 6.0)])  # from (3, 4)


def test_mitigation_filters_checks_copies_and_time():
    motion = models.ConstantVelocity2(0.1, 1.0, models.VelocityNoise.WhiteAcceleration)
    mean, cov = np.array([3.0, 4.0, 0.0, 0.0]), np.eye(4)
    f = mitigation.QpBiasEkf(motion, ANCHORS, mean, cov)
    with pytest.raises(ValueError, match=r"^z: expected shape \(3, 1\), got \(2, 1\)$"):
        f.step(EXACT[:2])
    Z = np.tile(EXACT, (3, 1))
    Z[1, 2] = np.inf
    with pytest.raises(ValueError, match=rf"^step 1: Z: {INF_ROW} 2$"):
        f.run(Z)
    assert f.time == 0.0
    np.testing.assert_array_equal(f.mean, mean)
    f.run(np.tile(EXACT, (3, 1)))
    t = f.time
    assert t == pytest.approx(0.2)
    f.set_belief(mean, cov)  # no t: the time stays
    assert f.time == t
    f.set_belief(mean, cov, t=1.0)
    assert f.time == 1.0
    b = f.bias
    m, c = f.belief()
    f.step(EXACT + np.array([0.0, 30.0, 0.0]))
    assert np.array_equal(b, np.zeros(3)) and np.array_equal(m, mean)  # copies, not views
    assert f.motion.dt == motion.dt
    g = mitigation.BiasAugmentedEkf(motion, ANCHORS, mean, cov)
    x = g.mean
    g.step(EXACT)
    assert not np.shares_memory(x, g.mean)
    assert g.num_anchors == 3
    np.testing.assert_array_equal(g.anchors, ANCHORS)
    assert g.options.iterations == mitigation.BiasAugmentedEkfOptions().iterations
    g.set_belief(mean, cov)
    assert g.time == pytest.approx(0.1)
    est = mitigation.BiasEstimator(ANCHORS)
    with pytest.raises(ValueError, match=rf"^z: {INF_ROW} 1$"):
        est.estimate_from_innovation(np.array([5.0, np.inf, 6.0]), np.zeros(3), np.eye(3))


def test_snapshot_estimators_reject_inf_and_expose_options():
    st = rtoa_stack()
    y = np.full(st.rows, 3000.0)
    y[1] = np.inf
    o = snapshot.ChenOptions()
    o.reject_fraction = 0.25
    gn = snapshot.GaussNewtonOptions()
    for est in (snapshot.MleLos(st), snapshot.Chen(st, o), snapshot.Cong(st), snapshot.Urruela(st)):
        with pytest.raises(ValueError, match=rf"^y: {INF_ROW} 1$"):
            est.solve(y)
        assert est.gauss_newton.max_iterations == gn.max_iterations
    assert snapshot.Chen(st, o).options.reject_fraction == 0.25
    assert snapshot.MleLos(st).options.max_iterations == gn.max_iterations


def test_filter_accessors_have_python_twins():
    H = np.eye(2, 4)
    kf = filters.Kf(MOTION, H, 2.0 * np.eye(2), X0, P0)
    np.testing.assert_array_equal(kf.H, H)
    np.testing.assert_array_equal(kf.R, 2.0 * np.eye(2))
    assert kf.rows == 2
    m, c = kf.belief()
    np.testing.assert_array_equal(m, X0)
    np.testing.assert_array_equal(c, P0)
    assert kf.motion.dt == MOTION.dt
    u = filters.Ukf(MOTION, stack(), X0, P0, core.SigmaScheme.scaled(0.5, 2.0, 0.0))
    assert u.scheme.alpha == 0.5
    assert u.weights.gamma == pytest.approx(0.5 * 2.0)  # alpha sqrt(n + kappa), n = 4
    a = filters.UkfAugmented(MOTION, stack(), X0, P0)
    assert a.augmented_dim == 4 + 3
    fwd = situation.ForwardFilter(SIGHT, QUALITY)
    p = fwd.probabilities
    fwd.update(np.full(6, 0.9))
    assert not np.array_equal(p, fwd.probabilities)  # p kept the old values: a copy


SEED_RANGE = r"expected an integer in \[0, 2\*\*64 - 1\], got "


def test_unsigned_arguments_name_themselves_when_out_of_range():
    from nlosloc import sim

    # pybind11's own uint64 conversion refused these with "incompatible function arguments".
    cases = [
        ("seed", "-1", lambda: sim.draw("K1", "2LOS/1NLOS", seed=-1, run=0)),
        ("run", "-2", lambda: sim.draw("K1", "2LOS/1NLOS", seed=1, run=-2)),
        ("run", "18446744073709551616", lambda: sim.K1().draw("2LOS/1NLOS", seed=1, run=2**64)),
        ("seed", "-1", lambda: sim.run_monte_carlo("K1", "2LOS/1NLOS", runs=1, seed=-1)),
        ("seed", "-1", lambda: sim.run_monte_carlo(sim.K1(), "2LOS/1NLOS", runs=1, seed=-1)),
        ("seed", "-5", lambda: sim.run_k2_study(1, -5)),
        ("seed", "-1", lambda: core.Rng(-1)),
        ("stream", "-1", lambda: core.Rng(0, -1)),
        ("seed", "-1", lambda: rbpf.PfOptions(seed=-1)),
        ("max_offspring", "-4", lambda: rbpf.RbpfOptions(max_offspring=-4)),
    ]
    for name, shown, call in cases:
        with pytest.raises(ValueError, match=rf"^{name}: {SEED_RANGE}{shown}$"):
            call()
    opt = rbpf.PfOptions(seed=3)
    with pytest.raises(ValueError, match=rf"^seed: {SEED_RANGE}-1$"):
        opt.seed = -1
    assert opt.seed == 3
    ro = rbpf.RbpfOptions()
    with pytest.raises(ValueError, match=rf"^max_offspring: {SEED_RANGE}-1$"):
        ro.max_offspring = -1
    assert ro.max_offspring == 4096
    # numpy integers and the largest value are accepted; a float is still a TypeError
    assert core.Rng(np.uint64(2**64 - 1))() == core.Rng(2**64 - 1)()
    assert rbpf.PfOptions(seed=np.int64(7)).seed == 7
    with pytest.raises(TypeError):
        core.Rng(1.0)


def test_non_finite_inputs_that_used_to_pass_silently_are_refused() -> None:
    """Each of these returned a plausible value before (found by an audit of the bindings)."""
    from nlosloc import sim

    # a NaN position read as "on the anchor" and gave |v|
    with pytest.raises(ValueError, match="p: expected finite values"):
        situation.transversal_speed([np.nan, 0.0], [1.0, 1.0], [0.0, 0.0])
    with pytest.raises(ValueError, match="anchors: expected finite values"):
        situation.transversal_speeds([1.0, 0.0], [1.0, 1.0], np.array([[0.0, np.inf]]))
    assert situation.transversal_speed([0.0, 0.0], [3.0, 4.0], [0.0, 0.0]) == 5.0  # on the anchor
    assert situation.transversal_speed([2.0, 0.0], [3.0, 4.0], [0.0, 0.0]) == 4.0  # eq. (10)
    # a 1-D array read as n runs of one step
    with pytest.raises(ValueError, match=r"errors: expected a 2-D \(runs, T\) array, got 1-D"):
        sim.rmse_over_time(np.array([1.0, 2.0, 3.0]))
    np.testing.assert_allclose(
        sim.rmse_over_time(np.array([[3.0, 0.0], [4.0, 0.0]])), [12.5**0.5, 0]
    )
    # a NaN start gave a "fix" of NaN with cost inf, or a valid fix from nowhere
    h2 = sim.H2()
    solver = snapshot.LosSolver(h2.measurements)
    y = np.full(h2.measurements.rows, 10.0)
    with pytest.raises(ValueError, match="theta0: expected finite values"):
        solver.solve(y, [np.nan, 0.0, 0.0])
    mle = snapshot.MleLos(h2.measurements)
    mle.reset([1.0, 2.0, 0.0])
    with pytest.raises(ValueError, match="start: expected finite values"):
        mle.reset([np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match="start: expected finite values"):
        snapshot.Chen(h2.measurements).reset([0.0, np.inf, 0.0])
    # a NaN hint was ignored (the least-squares fit was used instead)
    anchors = np.array([[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]])
    with pytest.raises(ValueError, match="hint: expected finite values"):
        mitigation.reference_point(anchors, np.array([50.0, 60.0, 70.0]), np.array([np.nan, 1.0]))
    # [0, 0) has no integer
    with pytest.raises(ValueError, match="n: expected an integer >= 1, got 0"):
        core.Rng(1).below(0)
    assert 0 <= core.Rng(1).below(3) < 3


def test_the_qp_bias_ekf_shows_its_bias_estimator() -> None:
    from nlosloc import sim

    k1 = sim.K1()
    d = k1.draw("0LOS/3NLOS", 1, 0, 20)
    o = mitigation.QpBiasEkfOptions()
    o.always_estimate = True
    f = mitigation.QpBiasEkf(k1.motion, k1.anchors, d["initial_mean"], d["initial_cov"], o)
    for k in range(20):
        f.step(d["y"][k])
    e = f.bias_estimator
    assert e.size == 3 and e.solver_name == f.solver_name
    np.testing.assert_array_equal(e.last.bias, f.bias)  # the bias of the last update
    assert e.last.qp.ok()
    assert (e.last.upper >= e.last.lower).all()
    e.sparsity = 0.5  # a copy: the tracker's own estimator is unchanged
    assert f.bias_estimator.sparsity == 0.0


def test_solver_internals_have_python_twins() -> None:
    from nlosloc import sim

    # RowNoise.normalized: the side's sigma (Cong & Zhuang's split normal)
    r = snapshot.RowNoise(1.0, 2.0, 4.0)
    assert r.normalized(0.0) == -0.5 and r.normalized(5.0) == 1.0
    # LosSolver: its stack and theta -> state in the stack's layout
    h2 = sim.H2()
    solver = snapshot.LosSolver(h2.measurements)
    assert solver.measurements.rows == h2.measurements.rows
    L = h2.measurements.layout
    x = solver.to_state([10.0, 20.0, 3.0])
    expected = np.zeros(L.dim)
    expected[L.position : L.position + 2] = [10.0, 20.0]
    expected[L.clock_bias] = 3.0
    np.testing.assert_array_equal(x, expected)
    with pytest.raises(ValueError, match=r"theta: expected shape \(3, 1\)"):
        solver.to_state([1.0, 2.0])
    # BoxQp: settings and the enumeration's active set
    s = mitigation.BoxQpSettings()
    s.eps_abs = 1e-7
    q = mitigation.make_box_qp(3, s, "enumeration")
    assert q.settings.eps_abs == 1e-7
    assert q.active_set == [0, 0, 0]
    assert mitigation.make_box_qp(3, s, "failing").settings is None
    assert mitigation.make_box_qp(3, s, "failing").active_set is None
    H = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 2.0]])
    g, lo, hi = np.array([-1.0, -1.0, 0.5]), np.zeros(3), np.full(3, 2.0)
    q.active_set = [0, 1, 1]  # x0 free first: the vertex [1, 0, 0] of the optimal segment
    assert q.solve(H, g, lo, hi).ok()
    np.testing.assert_array_equal(q.x, [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"active_set: expected entries 0 \(free\), 1 \(lower\)"):
        q.active_set = [0, 3, 1]
    with pytest.raises(ValueError, match="active_set: expected 3 entries, got 2"):
        q.active_set = [0, 1]
    with pytest.raises(ValueError, match="active_set: only the 'enumeration' solver has one"):
        mitigation.make_box_qp(3, s, "failing").active_set = [0, 0, 0]


def test_heavy_tailed_noise_is_refused_by_the_additive_filters_only() -> None:
    anchors = np.array([[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]])
    cv = models.ConstantVelocity2(0.1, 1.0)
    st = models.MeasurementStack(cv.layout(), anchors, 2)
    heavy = noise.Gev(0.6, 1.0, 1.0)  # shape >= 0.5: infinite variance
    for b in range(3):
        st.add_toa(b, [noise.Normal(0.0, 1.0), heavy if b == 1 else noise.Normal(5.0, 2.0)])
    x0, p0 = np.array([10.0, 20.0, 1.0, 0.0]), np.eye(4)
    for cls in (filters.Ekf, filters.Ukf):
        with pytest.raises(ValueError, match="row 1, condition 1: the noise Gev has mean"):
            cls(cv, st, x0, p0)
    f = filters.UkfAugmented(cv, st, x0, p0)  # quantiles, not moments: accepted
    f.update(np.array([22.4, 91.0, 80.6]), sight=[0, 1, 0])
    assert np.isfinite(f.mean).all()
    with pytest.raises(
        ValueError, match="dt, sigma2: the transition F or process noise Q overflows"
    ):
        models.ConstantVelocity2(10.0, 1e308)
    with pytest.raises(ValueError, match="spread too large"):
        noise.Empirical(np.array([0.0, 1e200, -1e200]))


# Finite, so reset and set_belief take it, but eq. (10)'s transversal speed overflows to NaN.
HUGE6 = np.array([1e160, 1e160, 0.0, 1e160, 1e160, 0.0])
OVERFLOW = r"the transversal speed \(eq. 10\) w.r.t. anchor 0 is -?nan: the state is not finite"


@pytest.mark.parametrize("threads", [1, 2])
def test_an_overflowed_state_is_a_numerical_error_that_changes_nothing(threads):
    # It was a ValueError naming an internal quantity ("w", "speeds"), though check_inputs passed.
    Y, Q, _, _ = track(steps=4)
    names = ("estimate", "covariance", "situation_probabilities", "time", "step_index")
    for variant, m in ((rbpf.RbpfVariant.Reordered, 16), (rbpf.RbpfVariant.Classical, 4)):
        opt = rbpf.RbpfOptions(variant=variant, num_particles=m, threads=threads)
        f = rbpf.Rbpf(MOTION6, stack6(), SIGHT, QUALITY, HUGE6, P06, opt)
        before = state(f, names)
        f.check_inputs(Y[0], Q[0])
        with pytest.raises(core.NumericalError, match=rf"^Rbpf.step: {OVERFLOW}"):
            f.step(Y[0], Q[0])
        assert_same(before, state(f, names))
        msg = rf"^step 0 \(the filter holds step -1\): Rbpf.step: {OVERFLOW}"
        with pytest.raises(core.NumericalError, match=msg):
            f.run(Y, Q)
        assert_same(before, state(f, names))
    f = rbpf.Iukf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06)
    f.step(Y[0], Q[0])
    f.set_belief(HUGE6, P06)
    before = state(f, ("mean", "cov", "time"))
    with pytest.raises(core.NumericalError, match=rf"^Iukf.step: {OVERFLOW}"):
        f.step(Y[1], Q[1])
    assert_same(before, state(f, ("mean", "cov", "time")))


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("generic", [False, True], ids=["fast sight", "generic sight"])
def test_a_rejected_pf_step_draws_nothing(threads, generic):
    # An overflowed state gives every particle zero likelihood. On the generic sight path (not every
    # chain speed-dependent) its NaN speed was a ValueError thrown from inside the pass, which had
    # already advanced the generators: the next step then differed from a twin's.
    Y, Q, _, _ = track(steps=3)
    sd = situation.SightModel.speed_dependent(10.0, 10.0, 0.01)
    fixed = situation.SightModel.fixed(np.array([[0.99, 0.01], [0.02, 0.98]]))
    sight = situation.SightProcess([sd] * 5 + [fixed]) if generic else SIGHT
    opt = rbpf.PfOptions(num_particles=500, threads=threads, seed=1)
    f = rbpf.ParticleFilter(MOTION6, stack6(), sight, QUALITY, HUGE6, P06, opt)
    twin = rbpf.ParticleFilter(MOTION6, stack6(), sight, QUALITY, HUGE6, P06, opt)
    fields = ("particles", "situations", "log_weights", "estimate", "covariance", "generators")
    before = [np.asarray(getattr(f.save(), n)) for n in fields]
    with pytest.raises(core.NumericalError, match="every particle has zero likelihood"):
        f.step(Y[0], Q[0])
    assert_same(before, [np.asarray(getattr(f.save(), n)) for n in fields])
    assert (f.time, f.step_index) == (0.0, 0)
    for g in (f, twin):
        g.reset(X06, P06)
    for k in range(3):
        f.step(Y[k], Q[k])
        twin.step(Y[k], Q[k])
        np.testing.assert_array_equal(f.estimate, twin.estimate)


def test_iukf_step_names_a_misshaped_o():
    Y, Q, _, _ = track(steps=1)
    f = rbpf.Iukf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06)
    with pytest.raises(ValueError, match=r"^o: expected a 1-D float array, got 2 dimensions$"):
        f.step(Y[0], Q[0].reshape(2, 3))
    with pytest.raises(ValueError, match=r"^o: expected a 1-D float array, got str$"):
        f.step(Y[0], "abcdef")
    # numpy reads a list of str as a str array, which it would parse
    with pytest.raises(ValueError, match=r"^o: expected real values, got a str array$"):
        f.step(Y[0], ["a"] * 6)
    with pytest.raises(ValueError, match=r"^o: expected shape \(6, 1\), got \(5, 1\)$"):
        f.step(Y[0], Q[0][:5])
    assert f.time == 0.0


def test_sim_helpers_name_bad_arguments():
    h1 = sim.H1()
    for theta in (np.nan, np.inf):  # they read as sector 0
        with pytest.raises(ValueError, match=r"^theta: expected a finite bearing \(rad\), got"):
            h1.serving_sector(theta)
    with pytest.raises(ValueError, match=r"^max_points: expected 0 \(all\) or >= 2, got -1$"):
        sim.ecdf(np.arange(5.0), -1)
    k1 = sim.scenario("K1")
    assert k1.paper_value("EKF", "2LOS/1NLOS", "p67") is not None
    assert k1.paper_value("EKF", "2LOS/1NLOS", "P67") is None  # no such metric published
    with pytest.raises(ValueError, match=r"^case: unknown case '2LOS/1NLSO' of scenario K1"):
        k1.paper_value("EKF", "2LOS/1NLSO", "p67")


def test_mle_los_says_an_underdetermined_epoch_has_no_fix():
    # 2 RTOA rows for 3 unknowns (p, tau): the Gauss-Newton point is one of many, as CHEN, CONG and
    # URR say (valid False); MLE-LOS said valid True.
    st = rtoa_stack()
    rng = np.random.default_rng(2)
    mle = snapshot.MleLos(st)
    y = np.linalg.norm(HEX - np.array([100.0, -50.0]), axis=1) + 5.0 + rng.normal(0, 1, 6)
    first = mle.solve(y)
    assert first["valid"]
    theta = np.array(first["theta"], copy=True)
    y2 = y.copy()
    y2[2:] = np.nan
    r = mle.solve(y2)
    assert not r["valid"]
    np.testing.assert_array_equal(r["theta"], theta)  # the previous fix
    y2[2] = y[2]  # three rows: determined
    assert mle.solve(y2)["valid"]


ONE_D = r"expected a 1-D float array, got "


def test_vector_arguments_name_themselves():
    # A (1, m) row sliced from a (T, m) array, a column (m, 1) and a complex vector: pybind11's
    # Eigen caster refused the first with "incompatible function arguments" (a TypeError naming no
    # argument) and dropped the imaginary part of the last with only a numpy warning.
    Y, Q, _, _ = track(steps=1)
    motion = models.ConstantVelocity2(0.1, 1.0, models.VelocityNoise.WhiteAcceleration)
    cases = [
        ("y", Y3, filters.Ekf(MOTION, stack(), X0, P0), lambda f, v: f.step(v)),
        ("y", Y3, filters.Ukf(MOTION, stack(), X0, P0), lambda f, v: f.update(v)),
        ("y", Y3, filters.UkfAugmented(MOTION, stack(), X0, P0), lambda f, v: f.step(v)),
        (
            "y",
            Y3[:2],
            filters.Kf(MOTION, np.eye(2, 4), np.eye(2), X0, P0),
            lambda f, v: f.update(v),
        ),
        ("z", EXACT, mitigation.QpBiasEkf(motion, ANCHORS, X0, P0), lambda f, v: f.step(v)),
        (
            "z",
            EXACT,
            mitigation.BiasAugmentedEkf(motion, ANCHORS, X0, P0),
            lambda f, v: f.update(v),
        ),
        ("o", Q[0], situation.ForwardFilter(SIGHT, QUALITY), lambda f, v: f.update(v)),
    ]
    for pf in particle_filters():
        cases.append(("y", Y[0], pf, lambda f, v: f.step(v, Q[0])))
        cases.append(("o", Q[0], pf, lambda f, v: f.check_inputs(Y[0], v)))
    iukf = rbpf.Iukf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06)
    cases.append(("y", Y[0], iukf, lambda f, v: f.step_quality(v, Q[0])))
    cases.append(
        ("y", Y[0], iukf, lambda f, v: f.update_with_probabilities(v, np.full((6, 2), 0.5)))
    )
    for name, good, f, call in cases:
        before = pickle.dumps(f)
        for bad, shown in ((good[None, :], "2 dimensions"), (good[:, None], "2 dimensions")):
            with pytest.raises(ValueError, match=rf"^{name}: {ONE_D}{shown}$"):
                call(f, bad)
        with pytest.raises(
            ValueError, match=rf"^{name}: expected real values, got a complex array$"
        ):
            call(f, good + 0j)
        with pytest.raises(ValueError, match=rf"^{name}: {ONE_D}None$"):
            call(f, None)
        assert pickle.dumps(f) == before, type(f).__name__
        call(f, list(good))  # a sequence of numbers still works


def test_index_arguments_beyond_int_are_named():
    # pybind11's int caster refused 2**31 with "incompatible function arguments" (a TypeError).
    f = rbpf.Rbpf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06, rbpf.RbpfOptions(num_particles=8))
    calls = (f.log_weight, f.particle_mean, f.particle_cov, f.particle_situation, stack().linear_h)
    for i in (2**31, 2**64, -(2**31) - 1, np.uint64(2**63)):
        for call in calls:
            with pytest.raises(
                IndexError, match=rf"^i: expected an index within the range of int, got {int(i)}$"
            ):
                call(i)
    n = f.num_particles
    for i in (n, -1, np.int64(-(2**31))):  # within int: the callee's own range check
        with pytest.raises(ValueError, match=rf"^i: expected a particle index in \[0, {n}\)$"):
            f.log_weight(i)
    assert f.log_weight(np.int32(0)) == f.log_weight(0)
    with pytest.raises(TypeError):
        f.log_weight(0.0)


def test_merge_keys_are_named_when_out_of_range():
    means, logw = np.zeros((1, 3)), np.log(np.full(3, 1.0 / 3.0))
    with pytest.raises(ValueError, match=rf"^keys\[1\]: {SEED_RANGE}-1$"):
        rbpf.merge_greedy([0, -1, 0], means, logw, 1.0)
    with pytest.raises(ValueError, match=rf"^keys\[2\]: {SEED_RANGE}{2**64}$"):
        rbpf.merge_greedy([0, 0, 2**64], means, logw, 1.0)
    new, n = rbpf.merge_greedy(np.array([5, 5, 5], dtype=np.uint64), means, logw, 1.0)
    assert n == 2
    assert new[0] == pytest.approx(0.0, abs=1e-15)


def test_an_empty_estimator_list_is_refused():
    from nlosloc import montecarlo

    msg = r"^estimators: expected at least one estimator, got an empty list \(None: every estimator"
    with pytest.raises(ValueError, match=msg):
        sim.run_monte_carlo("K1", "2LOS/1NLOS", runs=1, seed=1, estimators=[])
    with pytest.raises(ValueError, match=msg):
        sim.run_monte_carlo(sim.K1(), "2LOS/1NLOS", runs=1, seed=1, estimators=())
    with pytest.raises(ValueError, match=msg):
        montecarlo.run("K1", "2LOS/1NLOS", 1, 1, [], progress=False)


def test_core_and_sim_inputs_found_by_an_api_check() -> None:
    """Each was taken silently, crashed, or gave a wrong value before."""
    # a 0 x 0 matrix crashed the interpreter (Eigen's minCoeff on it); it is PD vacuously
    e = np.zeros((0, 0))
    assert core.is_spd(e) and core.is_spsd(e)
    L, status, jitter = core.robust_cholesky(e)
    assert L.shape == (0, 0) and status == core.CholeskyStatus.Ok and jitter == 0.0
    # the tolerance of is_spd / is_spsd is checked (NaN passed a non-symmetric matrix)
    for tol in (np.nan, -1.0, np.inf):
        with pytest.raises(ValueError, match="^rel_tol: expected a finite value >= 0, got "):
            core.is_spd(np.array([[2.0, 1.0], [0.0, 2.0]]), tol)
        with pytest.raises(ValueError, match="^rel_tol: expected a finite value >= 0, got "):
            core.is_spsd(-np.eye(2), tol)
    # sigma_points: a non-finite mean, a non-symmetric covariance (its symmetric part was used)
    scheme = core.SigmaScheme.scaled(0.5)
    with pytest.raises(ValueError, match=r"^mean: expected finite values \(no NaN or inf\)$"):
        core.sigma_points(np.array([0.0, np.nan]), np.eye(2), scheme)
    with pytest.raises(ValueError, match=r"^cov: expected a finite symmetric matrix"):
        core.sigma_points(np.zeros(2), np.array([[1.0, 0.9], [-0.9, 1.0]]), scheme)
    # a scheme compares unequal to anything else (== None raised TypeError)
    assert scheme != None and not (scheme == 3) and scheme in [None, scheme]  # noqa: E711
    # eq. (52) has no kappa: the Huerta kind refuses one (+10 was ignored)
    with pytest.raises(ValueError, match=r"kappa: expected 0 for the Huerta rule \(eq\. 52\)"):
        core.SigmaScheme(core.SigmaScheme.Kind.Huerta, 0.5, 2.0, 10.0).weights(4)
    # percentiles between -inf and a finite rank (NaN before)
    np.testing.assert_array_equal(
        sim.percentiles(np.array([-np.inf, 1.0, 2.0]), [0, 25, 50]), [-np.inf, -np.inf, 1.0]
    )
    # the ECDF counts ties: P(error <= 2) = 0.6 here (0.4 at the first 2 before)
    v = np.array([3.0, 1.0, 2.0, 2.0, 5.0])
    for x, p in (sim.ecdf(v), montecarlo.ecdf(v)):
        np.testing.assert_array_equal(x, [1, 2, 2, 3, 5])
        np.testing.assert_allclose(p, [0.2, 0.6, 0.6, 0.8, 1.0], rtol=0, atol=1e-15)
        np.testing.assert_array_equal(p, [np.mean(v <= t) for t in x])
    _, p = montecarlo.ecdf(np.array([2.0, np.nan, 2.0]))
    np.testing.assert_allclose(p, [2 / 3, 2 / 3, 1.0])
    # backdate refuses what is not a belief (a NaN mean came back NaN, -P as a start)
    mo = models.ConstantVelocity2(0.5, 2.0)
    with pytest.raises(ValueError, match=r"^mean: expected finite values"):
        sim.backdate(mo, np.array([0.0, np.nan, 0.0, 0.0]), np.eye(4))
    with pytest.raises(ValueError, match="^cov: expected a symmetric positive definite matrix$"):
        sim.backdate(mo, np.zeros(4), -np.eye(4))
    # the K2 study refuses runs no longer than the discard, as run_monte_carlo (all-NaN tables)
    with pytest.raises(
        ValueError, match=r"^steps: expected more than the scenario's 100 discarded"
    ):
        sim.run_k2_study(1, 1, steps=50)
    # counts are integers, not True
    for kw in (dict(runs=True), dict(threads=True), dict(steps=True)):
        args = dict(runs=1, threads=1, steps=110) | kw
        (name,) = kw
        with pytest.raises(TypeError, match=rf"^{name}: expected an integer, got True \(bool\)$"):
            sim.run_monte_carlo(
                "K1",
                "3LOS/0NLOS",
                args["runs"],
                1,
                ["EKF"],
                threads=args["threads"],
                steps=args["steps"],
            )
    with pytest.raises(TypeError, match=r"^steps: expected an integer, got True"):
        sim.draw("K1", "3LOS/0NLOS", 1, 0, steps=True)
    with pytest.raises(TypeError, match=r"^runs: expected an integer, got True"):
        sim.run_k2_study(True, 1)
