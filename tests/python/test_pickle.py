"""Models pickle (nlosloc/_pickle.py): measurement stacks with every kind of row, sight chains and
processes, quality models; each copy predicts, draws and scores as the original."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from box_qp_helpers import Enumeration
from nlosloc import core, models, noise, sim, situation


def roundtrip(obj):
    return pickle.loads(pickle.dumps(obj))


def same_stack(a: models.MeasurementStack, b: models.MeasurementStack, x: np.ndarray) -> None:
    assert (b.rows, b.noise_dim, b.num_conditions) == (a.rows, a.noise_dim, a.num_conditions)
    np.testing.assert_array_equal(b.anchors, a.anchors)
    for i in range(a.rows):
        ra, rb = a.row(i), b.row(i)
        fields = ["kind", "anchor", "anchor2", "input", "inputs", "sector_center", "slot", "linear"]
        for f in fields:
            assert getattr(rb, f) == getattr(ra, f), (i, f)
    np.testing.assert_array_equal(b.predict(x, 0.3), a.predict(x, 0.3))
    np.testing.assert_array_equal(b.jacobian(x, 0.3), a.jacobian(x, 0.3))
    u = np.linspace(0.1, 0.9, a.noise_dim)
    for s in [np.zeros(a.num_anchors, int), np.ones(a.num_anchors, int)]:
        for m, n in zip(a.noise_moments(x, s), b.noise_moments(x, s)):
            np.testing.assert_array_equal(n, m)
        np.testing.assert_array_equal(
            b.predict_augmented(x, 0.3, u, s), a.predict_augmented(x, 0.3, u, s)
        )


def test_a_stack_with_every_row_kind_pickles() -> None:
    anchors = np.array([[0.0, 0.0], [100.0, 0.0], [0.0, 80.0]])
    layout = models.ConstantVelocityClock2.layout()
    emp = noise.Empirical(np.array([1.0, 2.5, 4.0, 9.0, 3.0]))
    m = models.MeasurementStack(layout, anchors, 2)
    m.add_toa(0, [noise.Normal(0.0, 1.0), noise.Rayleigh(30.0)])
    m.add_rtoa(1, [noise.Normal(0.0, 2.0), emp])
    m.add_aoa(2, [noise.Normal(0.0, 0.01), noise.Normal(0.0, 0.1)])
    m.add_aoa_phase(0, 0.7, [noise.Normal(0.0, 0.02), noise.Normal(0.0, 0.2)])
    m.add_tdoa(1, 2, [noise.Normal(0.0, 1.0), noise.Exponential(5.0)], [noise.Normal(0, 3.0), emp])
    m.add_linear(np.array([0.0, 0.0, 1.0, 0.5, 0.0, 0.0]), -1, [noise.Normal(0, 1.0)] * 2)
    x = np.array([30.0, 40.0, 5.0, 1.0, -2.0, 0.1])
    same_stack(m, roundtrip(m), x)
    assert [m.row(i).linear for i in range(m.rows)] == [-1] * (m.rows - 1) + [0]
    assert roundtrip(m).noise_b(4, 1).mean() == emp.mean()
    # two-way ranging (Grisales eqs. 17-20) on the TwoWayClock state
    t = models.MeasurementStack(models.TwoWayClock.layout(), anchors, 3)
    for b in range(3):
        t.add_twr(b, b, 1e-3, 2e-4, 1e-9, [None, noise.Exponential(3e-8), noise.Rayleigh(5e-8)])
    t.add_toa(0, [noise.Normal(0.0, 1.0)] * 3)
    xt = np.array([1.00001, 2e-6, 1.0, -0.5, 20.0, 30.0])
    c = roundtrip(t)
    same_stack(t, c, xt)
    w = c.twr_params(2)
    assert (w.delta_slot, w.reply_delay, w.sigma_m) == (1e-3, 2e-4, 1e-9)
    assert w.gamma[0] is None and w.gamma[2].mean() == t.twr_params(2).gamma[2].mean()


def test_the_scenarios_stacks_pickle() -> None:
    for s, x in [
        (sim.H1(), np.array([-300.0, 200.0, 10.0, 0.0])),
        (sim.H2(), np.array([20.0, 30.0, 5.0, 1.0, 0.0, 0.1])),
        (sim.K1(), np.array([1000.0, 900.0, 10.0, 15.0])),
    ]:
        same_stack(s.measurements, roundtrip(s.measurements), x)


def test_sight_models_processes_and_quality_pickle() -> None:
    fixed = situation.SightModel.fixed(
        np.array([[0.9, 0.05, 0.05], [0.2, 0.7, 0.1], [0.1, 0.1, 0.8]]),
        5,
        np.array([0.5, 0.3, 0.2]),
    )
    stationary = situation.SightModel.fixed(np.array([[0.95, 0.05], [0.3, 0.7]]))
    speeds = [
        situation.SightModel.speed_dependent(30.0, 5.0, 0.01, form)
        for form in [
            situation.SpeedModel.Single,
            situation.SpeedModel.Multiple,
            situation.SpeedModel.Memoryless,
        ]
    ]
    for a in [fixed, stationary, *speeds]:
        b = roundtrip(a)
        assert (b.is_speed_dependent, b.k_sight, b.num_conditions) == (
            a.is_speed_dependent,
            a.k_sight,
            a.num_conditions,
        )
        np.testing.assert_array_equal(b.initial, a.initial)
        for k, w in [(1, 0.0), (5, 3.0), (7, 12.5)]:
            np.testing.assert_array_equal(b.transition(k, w), a.transition(k, w))
    process = situation.SightProcess([speeds[1], speeds[0], speeds[1]])
    copy = roundtrip(process)
    assert copy.num_anchors == 3
    r1, r2 = core.Rng(3, 0), core.Rng(3, 0)
    s1, s2 = process.sample_initial(r1), copy.sample_initial(r2)
    np.testing.assert_array_equal(s1, s2)
    w = np.array([4.0, 9.0, 1.0])
    for k in range(1, 30):
        s1, s2 = process.sample_next(s1, k, w, r1), copy.sample_next(s2, k, w, r2)
        np.testing.assert_array_equal(s1, s2)
    q = situation.QualityModel([noise.Beta(4.0, 1.5), noise.Beta(1.5, 4.0)])
    qc = roundtrip(q)
    for o in [0.1, 0.5, 0.93]:
        assert [qc.log_likelihood(o, z) for z in range(2)] == [
            q.log_likelihood(o, z) for z in range(2)
        ]


def test_kalman_filters_pickle_and_step_on_as_the_original() -> None:
    from nlosloc import filters

    h2 = sim.H2()
    d = h2.draw("default", 4, 0, 40)
    m0, p0 = d["initial_mean"], d["initial_cov"]
    made = [
        filters.Ekf(h2.motion, h2.measurements, m0, p0),
        filters.Ukf(h2.motion, h2.measurements, m0, p0, core.SigmaScheme.julier(1.0)),
        filters.UkfAugmented(h2.motion, h2.measurements, m0, p0, core.SigmaScheme.scaled(0.5)),
        filters.Kf(h2.motion, np.eye(2, 6), np.eye(2) * 4.0, m0, p0, 0.5),
    ]
    for f in made:
        y = d["y"] if not isinstance(f, filters.Kf) else d["positions"] + 1.0
        f.update(y[0])
        for k in range(1, 20):
            f.step(y[k])
        g = roundtrip(f)
        assert type(g) is type(f) and g.time == f.time
        np.testing.assert_array_equal(g.mean, f.mean)
        np.testing.assert_array_equal(g.cov, f.cov)
        for k in range(20, 40):
            f.step(y[k])
            g.step(y[k])
        np.testing.assert_array_equal(g.mean, f.mean)
        np.testing.assert_array_equal(g.cov, f.cov)


def test_the_iukf_and_its_forward_filter_pickle_mid_run() -> None:
    from nlosloc import rbpf

    for s in [sim.H1(), sim.H2()]:
        d = s.draw("default", 2, 0, 60)
        q = situation.QualityModel(s.quality)
        f = rbpf.Iukf(
            s.motion, s.measurements, s.sight_process, q, d["initial_mean"], d["initial_cov"]
        )
        for k in range(30):
            f.step_quality(d["y"][k], d["quality"][k])
        g = roundtrip(f)
        assert g.forward.step_index == f.forward.step_index == 30
        np.testing.assert_array_equal(g.situation_probabilities, f.situation_probabilities)
        for k in range(30, 60):
            f.step_quality(d["y"][k], d["quality"][k])
            g.step_quality(d["y"][k], d["quality"][k])
        np.testing.assert_array_equal(g.mean, f.mean)
        np.testing.assert_array_equal(g.cov, f.cov)
        np.testing.assert_array_equal(g.situation_probabilities, f.situation_probabilities)
        assert g.forward.last_log_evidence == f.forward.last_log_evidence
        fw = roundtrip(f.forward)  # alone, too
        np.testing.assert_array_equal(fw.probabilities, f.forward.probabilities)
        np.testing.assert_array_equal(fw.predicted, f.forward.predicted)


def test_a_snapshot_built_by_hand_is_checked() -> None:
    g = np.array([[0.7, 0.3], [0.2, 0.8]])
    snap = situation.ForwardFilterSnapshot(g, g, 4, -1.5)
    h2 = sim.H2()
    process = situation.SightProcess(h2.sight_process.model(0), 2)
    f = situation.ForwardFilter(process, situation.QualityModel(h2.quality))
    f.restore(snap)
    assert f.step_index == 4 and f.last_log_evidence == -1.5
    np.testing.assert_array_equal(f.probabilities, g)
    with pytest.raises(ValueError, match="gamma: every row must hold probabilities"):
        situation.ForwardFilterSnapshot(np.array([[0.7, 0.4]]), np.array([[0.5, 0.5]]), 0, 0.0)
    with pytest.raises(ValueError, match=r"pred: expected shape \(2, 2\)"):
        situation.ForwardFilterSnapshot(g, g[:1], 0, 0.0)
    with pytest.raises(ValueError, match="k: expected a step index >= 0"):
        situation.ForwardFilterSnapshot(g, g, -1, 0.0)
    with pytest.raises(ValueError, match=r"gamma: expected a \(B, N_z\) array"):
        situation.ForwardFilterSnapshot(np.zeros((0, 2)), np.zeros((0, 2)), 0, 0.0)
    # as ForwardFilter.restore: finite (it took +inf, which restore() refused, and -inf, which no
    # update gives: a statistic of zero or infinite density is refused)
    for v, text in ((np.nan, "nan"), (np.inf, "inf"), (-np.inf, "-inf")):
        with pytest.raises(
            ValueError, match=f"^log_evidence: expected a finite value, got {text}$"
        ):
            situation.ForwardFilterSnapshot(g, g, 0, v)


def ke_wu_trackers(s: sim.Scenario, d: dict) -> list:
    from nlosloc import mitigation

    m0, p0 = d["initial_mean"], d["initial_cov"]
    A = s.anchors
    every_step = mitigation.QpBiasEkfOptions()
    every_step.always_estimate = True
    snapshot = mitigation.QpBiasEkfOptions()
    snapshot.reference = mitigation.BiasReference.Snapshot
    snapshot.always_estimate = True
    made = [
        mitigation.QpBiasEkf(s.motion, A, m0, p0),  # its own choice: the enumeration
        mitigation.QpBiasEkf(s.motion, A, m0, p0, every_step, Enumeration(len(A))),
        # Sec. 3's snapshot form: a rank-deficient QP, whose answer depends on the active set kept
        mitigation.QpBiasEkf(s.motion, A, m0, p0, snapshot, "enumeration"),
        mitigation.BiasAugmentedEkf(s.motion, A, m0, p0),
    ]
    if mitigation.have_proxsuite_box_qp:
        made.append(mitigation.QpBiasEkf(s.motion, A, m0, p0, snapshot, "proxsuite"))
    return made


@pytest.mark.parametrize("name,case", [("K1", "1LOS/2NLOS"), ("K3", "bad/4NLOS")])
def test_the_ke_wu_trackers_pickle_and_step_on_as_the_original(name: str, case: str) -> None:
    from nlosloc import mitigation

    s = {"K1": sim.K1, "K3": sim.K3}[name]()
    d = s.draw(case, 2, 0, 60)
    y = d["y"]
    for f in ke_wu_trackers(s, d):
        f.update(y[0])
        for k in range(1, 30):
            f.step(y[k])
        g = roundtrip(f)
        assert (
            type(g) is type(f) and g.time == f.time and g.options.__class__ is f.options.__class__
        )
        np.testing.assert_array_equal(g.mean, f.mean)
        np.testing.assert_array_equal(g.cov, f.cov)
        if isinstance(f, mitigation.QpBiasEkf):
            assert g.solver_name == f.solver_name
            assert not g.last_step.bias_estimated  # the last update's report is not kept
        h = __import__("copy").deepcopy(f)  # keeps it
        np.testing.assert_array_equal(h.bias, f.bias)
        ran = 0
        for k in range(30, 60):
            for t in (f, g, h):
                t.step(y[k])
            if isinstance(f, mitigation.QpBiasEkf):
                ran += f.last_step.bias_estimated
                assert g.last_step.flags == f.last_step.flags
        for t in (g, h):
            np.testing.assert_array_equal(t.mean, f.mean)
            np.testing.assert_array_equal(t.cov, f.cov)
            np.testing.assert_array_equal(t.bias, f.bias)
        if isinstance(f, mitigation.QpBiasEkf):
            # the QP ran (K3's NLOS rows rarely pass the test of eq. 32 in these steps)
            assert ran >= 5 or (name == "K3" and not f.options.always_estimate)
    # the Python solver travelled as a copy of the object, calls included
    f = ke_wu_trackers(s, d)[1]
    f.step(y[1])
    assert f.solver.calls == 1 and roundtrip(f).solver.calls == 1


def test_box_qp_solvers_pickle_with_the_active_set_they_start_from() -> None:
    from nlosloc import mitigation

    settings = mitigation.BoxQpSettings()
    settings.eps_abs = 1e-7
    q = mitigation.make_box_qp(3, settings, "enumeration")
    lo, hi = np.zeros(3), np.full(3, 2.0)
    # a first solve leaves x0 free and x1, x2 at their lower bounds: the active set kept
    assert q.solve(np.eye(3), np.array([-1.0, 1.0, 1.0]), lo, hi).ok()
    np.testing.assert_array_equal(q.x, [1.0, 0.0, 0.0])
    c = pickle.loads(pickle.dumps(q))
    assert (c.name, c.size) == ("enumeration", 3)
    np.testing.assert_array_equal(c.x, np.zeros(3))  # x, the last solve's report, is not kept
    # singular H: the optimal set is the segment x0 + x1 = 1, x2 = 0; the vertex returned is the one
    # the search reaches first, from the kept active set ([1, 0, 0]) or from all-free ([0, 1, 0])
    H = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 2.0]])
    g = np.array([-1.0, -1.0, 0.5])
    assert c.solve(H, g, lo, hi).ok()
    np.testing.assert_array_equal(c.x, [1.0, 0.0, 0.0])
    fresh = mitigation.make_box_qp(3, settings, "enumeration")
    assert fresh.solve(H, g, lo, hi).ok()
    np.testing.assert_array_equal(fresh.x, [0.0, 1.0, 0.0])
    names = ["enumeration", "failing"] + (["proxsuite"] if mitigation.have_proxsuite_box_qp else [])
    for name in names:
        r = pickle.loads(pickle.dumps(mitigation.make_box_qp(4, settings, name)))
        assert r.size == 4 and r.name == mitigation.make_box_qp(4, settings, name).name


def test_a_box_qp_object_is_a_solver_argument_and_bad_beliefs_are_refused() -> None:
    from nlosloc import mitigation

    s = sim.K1()
    d = s.draw("1LOS/2NLOS", 2, 0, 5)
    m0, p0 = d["initial_mean"], d["initial_cov"]
    q = mitigation.make_box_qp(3, solver="enumeration")
    f = mitigation.QpBiasEkf(s.motion, s.anchors, m0, p0, mitigation.QpBiasEkfOptions(), q)
    assert f.solver_name == "enumeration" and f.solver is not q
    assert mitigation.BiasEstimator(s.anchors, q).solver_name == "enumeration"
    with pytest.raises(
        ValueError,
        match=r"solver: expected a BoxQp of size 3 \(one variable per anchor\), got size 4",
    ):
        mitigation.QpBiasEkf(
            s.motion,
            s.anchors,
            m0,
            p0,
            mitigation.QpBiasEkfOptions(),
            mitigation.make_box_qp(4, solver="enumeration"),
        )

    b = mitigation.BiasAugmentedEkf(s.motion, s.anchors, m0, p0)
    b.step(d["y"][1])
    mean, cov, t = b.mean, b.cov, b.time
    with pytest.raises(ValueError, match=r"mean: expected shape \(7, 1\)"):
        b.set_augmented_belief(np.zeros(4), np.eye(4))
    bad = cov.copy()
    bad[0, 1] += 1.0
    with pytest.raises(
        ValueError, match="belief.cov: expected a symmetric positive definite matrix"
    ):
        b.set_augmented_belief(mean, bad)
    with pytest.raises(ValueError, match="t: expected a finite time"):
        b.set_augmented_belief(mean, cov, float("nan"))
    np.testing.assert_array_equal(b.mean, mean)
    np.testing.assert_array_equal(b.cov, cov)
    assert b.time == t
    b.set_augmented_belief(mean + 1.0, cov * 2.0, 7.5)
    np.testing.assert_array_equal(b.mean, mean + 1.0)
    assert b.time == 7.5 and b.bias[0] == mean[4] + 1.0


RBPF_SNAPSHOT_FIELDS = (
    "situations",
    "means",
    "covs",
    "log_weights",
    "situation_probabilities",
    "estimate",
    "covariance",
    "time",
    "step",
)
PF_SNAPSHOT_FIELDS = (
    "particles",
    "situations",
    "log_weights",
    "situation_probabilities",
    "estimate",
    "covariance",
    "position_variance",
    "generators",
    "time",
    "step",
)


def snapshot_with(s, fields: tuple[str, ...], **change):
    """A new snapshot of s's class (through its constructor): s's fields, some of them changed."""
    values = {f: getattr(s, f) for f in fields}
    values.update(change)
    return type(s)(**values)


def h2_rbpf(variant: str, particles: int, threads: int = 1):
    from nlosloc import rbpf

    s = sim.H2()
    o = rbpf.RbpfOptions()
    o.variant = {"reordered": rbpf.RbpfVariant.Reordered, "classical": rbpf.RbpfVariant.Classical}[
        variant
    ]
    o.num_particles = particles
    o.threads = threads
    q = situation.QualityModel(s.quality)
    d = s.draw("default", 6, 0, 50)
    f = rbpf.Rbpf(
        s.motion, s.measurements, s.sight_process, q, d["initial_mean"], d["initial_cov"], o
    )
    return f, d


def same_rbpf(a, b) -> None:
    assert (a.num_particles, a.step_index, a.time) == (b.num_particles, b.step_index, b.time)
    np.testing.assert_array_equal(a.estimate, b.estimate)
    np.testing.assert_array_equal(a.covariance, b.covariance)
    np.testing.assert_array_equal(a.situation_probabilities, b.situation_probabilities)
    for i in range(a.num_particles):
        assert a.log_weight(i) == b.log_weight(i)
        np.testing.assert_array_equal(a.particle_mean(i), b.particle_mean(i))
        np.testing.assert_array_equal(a.particle_cov(i), b.particle_cov(i))
        np.testing.assert_array_equal(a.particle_situation(i), b.particle_situation(i))


@pytest.mark.parametrize("variant,particles", [("reordered", 16), ("classical", 2)])
def test_the_rbpf_pickles_mid_track_and_steps_on_bit_for_bit(variant: str, particles: int) -> None:
    f, d = h2_rbpf(variant, particles, threads=2)
    y, o = d["y"], d["quality"]
    g0 = roundtrip(f)  # at the start: the next step draws from the initial sight
    same_rbpf(g0, f)
    for k in range(25):
        f.step(y[k], o[k])
        g0.step(y[k], o[k])
    same_rbpf(g0, f)
    g = roundtrip(f)
    assert g.options.threads == 2 and g.options.num_particles == particles
    same_rbpf(g, f)
    s = f.save()
    assert (
        s.step == 25
        and s.situations.shape == (f.num_particles, 6)
        and len(s.covs) == s.means.shape[0]
    )
    for k in range(25, 50):
        f.step(y[k], o[k])
        g.step(y[k], o[k])
    same_rbpf(g, f)
    # a snapshot pickles too, and puts a filter built elsewhere back at step 25
    h, _ = h2_rbpf(variant, particles)
    h.restore(pickle.loads(pickle.dumps(s)))
    assert h.step_index == 25
    np.testing.assert_array_equal(h.estimate, s.estimate)


def test_an_rbpf_snapshot_is_checked_by_restore() -> None:

    f, d = h2_rbpf("reordered", 8)
    for k in range(10):
        f.step(d["y"][k], d["quality"][k])
    s = f.save()

    def edited(**change):
        return snapshot_with(s, RBPF_SNAPSHOT_FIELDS, **change)

    bad_sit = s.situations.copy()
    bad_sit[0, 0] = 2
    bad_cov = [c.copy() for c in s.covs]
    bad_cov[1][0, 1] += 1.0
    cases = [
        (edited(situations=bad_sit), "snapshot.situations: expected condition indices 0 to 1"),
        (
            edited(covs=bad_cov),
            r"snapshot.covs\[1\]: expected a symmetric positive definite matrix",
        ),
        (edited(covs=np.array(s.covs)[:-1]), "snapshot.covs: expected 8 covariances, got 7"),
        (edited(log_weights=s.log_weights + 1.0), "expected normalised log weights"),
        (edited(step=-2), "snapshot.step: expected >= 0, got -2"),
        (edited(means=s.means[:, :4]), r"snapshot.means: expected shape \(8, 6\)"),
    ]
    before = f.save()
    for snap, message in cases:
        with pytest.raises(ValueError, match=message):
            f.restore(snap)
        np.testing.assert_array_equal(f.save().means, before.means)
        assert f.step_index == 10
    f.restore(edited(covs=np.array(s.covs)))  # one (P, n, n) array is a list of covariances too
    np.testing.assert_array_equal(f.save().covs[3], s.covs[3])


def h2_pf(resampling: str, threads: int, seed: int = 3):
    from nlosloc import rbpf

    s = sim.H2()
    o = rbpf.PfOptions(num_particles=3000, threads=threads, seed=seed)
    kinds = {"systematic": rbpf.PfResampling.Systematic, "merge": rbpf.PfResampling.MergeSelect}
    o.resampling = kinds[resampling]
    d = s.draw("default", 6, 0, 40)
    q = situation.QualityModel(s.quality)
    f = rbpf.ParticleFilter(
        s.motion, s.measurements, s.sight_process, q, d["initial_mean"], d["initial_cov"], o
    )
    return f, d


def same_pf(a, b) -> None:
    assert (a.num_particles, a.step_index, a.time) == (b.num_particles, b.step_index, b.time)
    np.testing.assert_array_equal(a.particles, b.particles)
    np.testing.assert_array_equal(a.situations, b.situations)
    np.testing.assert_array_equal(a.log_weights, b.log_weights)
    np.testing.assert_array_equal(a.estimate, b.estimate)
    np.testing.assert_array_equal(a.covariance, b.covariance)
    np.testing.assert_array_equal(a.situation_probabilities, b.situation_probabilities)


@pytest.mark.parametrize("resampling,threads", [("systematic", 1), ("merge", 2)])
def test_the_joint_pf_pickles_mid_track_and_steps_on_bit_for_bit(
    resampling: str, threads: int
) -> None:
    from nlosloc import rbpf

    f, d = h2_pf(resampling, threads)
    y, o = d["y"], d["quality"]
    for k in range(15):
        f.step(y[k], o[k])
    g = roundtrip(f)
    assert g.options.threads == threads and g.options.resampling == f.options.resampling
    same_pf(g, f)
    s = f.save()
    assert s.step == 15 and s.particles.shape == (6, 3000) and s.situations.shape == (6, 3000)
    assert len(s.generators) == threads * rbpf.PfSnapshot.GENERATOR_WORDS
    for k in range(15, 40):
        f.step(y[k], o[k])
        g.step(y[k], o[k])
    same_pf(g, f)
    # a snapshot pickles too, and puts a filter with another seed back at step 15: it draws as f did
    h, _ = h2_pf(resampling, threads, seed=11)
    h.restore(pickle.loads(pickle.dumps(s)))
    assert h.step_index == 15
    for k in range(15, 40):
        h.step(y[k], o[k])
    same_pf(h, f)


def test_a_pf_snapshot_is_checked_by_restore() -> None:

    f, d = h2_pf("systematic", 2)
    for k in range(5):
        f.step(d["y"][k], d["quality"][k])
    s = f.save()

    def edited(**change):
        return snapshot_with(s, PF_SNAPSHOT_FIELDS, **change)

    bad_sit = s.situations.copy()
    bad_sit[0, 0] = 2
    zero_lane = list(s.generators)
    zero_lane[6:22] = [0] * 16  # thread 0's BatchRng state (after its Rng's 6 words): a fixed point
    cases = [
        (edited(situations=bad_sit), "snapshot.situations: expected condition indices 0 to 1"),
        (edited(particles=s.particles[:, :-1]), r"snapshot.particles: expected shape \(6, 3000\)"),
        (edited(log_weights=s.log_weights + 1.0), "expected normalised log weights"),
        (edited(position_variance=float("nan")), "snapshot.position_variance: expected a finite"),
        (
            edited(generators=s.generators[:-1]),
            r"snapshot.generators: expected 87 words for each of the filter's 2 threads \(174\), "
            "got 173",
        ),
        (edited(generators=zero_lane), "snapshot.generators: thread 0's words are no generator"),
        (edited(step=-2), "snapshot.step: expected >= 0, got -2"),
    ]
    before = f.save()
    for snap, message in cases:
        with pytest.raises(ValueError, match=message):
            f.restore(snap)
        after = f.save()
        np.testing.assert_array_equal(after.particles, before.particles)
        assert after.generators == before.generators and f.step_index == 5
    # a snapshot of the filter's own state is accepted, and leaves it as it was
    f.restore(edited())
    np.testing.assert_array_equal(f.save().particles, before.particles)
