"""Monte Carlo runs split into chunks: first_run, montecarlo.merge, and run(executor=...)."""

from __future__ import annotations

import multiprocessing
import pickle
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

from nlosloc import core, mitigation, models, montecarlo, rbpf, sim, situation, snapshot

CASE = "2LOS/1NLOS"
STEPS = 110  # K1 leaves out its first 100 samples


class NoisyTruth:
    """The true position plus a draw of the estimator's own generator (module level: it pickles)."""

    def __init__(self, scenario: sim.Scenario, case_index: int) -> None:
        pass

    def reset(self, draw: dict, rng: core.Rng) -> None:
        self.positions = draw["positions"]
        self.rng = rng

    def step(self, k: int, y: np.ndarray, o: np.ndarray) -> np.ndarray:
        self.k = k
        return self.positions[k] + np.array([self.rng.normal(), 0.0])

    def sight_estimate(self) -> list[int]:
        return [0, 0, self.k % 2]


ESTIMATORS = ["EKF", ("noisy", NoisyTruth)]


@pytest.fixture(scope="module")
def full() -> dict:
    return sim.run_monte_carlo("K1", CASE, 6, 3, ESTIMATORS, steps=STEPS)


def assert_same_runs(a: dict, b: dict) -> None:
    assert list(a["estimators"]) == list(b["estimators"])
    for name, e in a["estimators"].items():
        assert set(e) == set(b["estimators"][name])
        for field in ("errors", "sight_accuracy", "sight_anchor_accuracy"):
            if field in e:
                np.testing.assert_array_equal(e[field], b["estimators"][name][field])
        assert len(e["time_per_step_ns"]) == len(b["estimators"][name]["time_per_step_ns"])
    for key in ("scenario", "case", "seed", "steps", "discard", "dt", "runs", "first_run"):
        assert a[key] == b[key], key


def test_first_run_gives_the_same_runs_as_a_run_from_zero(full: dict) -> None:
    assert full["first_run"] == 0
    part = sim.run_monte_carlo("K1", CASE, 3, 3, ESTIMATORS, steps=STEPS, first_run=2)
    assert (part["first_run"], part["runs"]) == (2, 3)
    for name in ("EKF", "noisy"):
        np.testing.assert_array_equal(
            part["estimators"][name]["errors"], full["estimators"][name]["errors"][2:5]
        )
    np.testing.assert_array_equal(
        part["estimators"]["noisy"]["sight_accuracy"],
        full["estimators"]["noisy"]["sight_accuracy"][2:5],
    )
    # the noisy estimator's draws are those of Rng(estimator_seed(seed, name), run)
    rng = core.Rng(sim.estimator_seed(3, "noisy"), 4)
    expected = [abs(rng.normal()) for _ in range(STEPS)]
    np.testing.assert_allclose(
        part["estimators"]["noisy"]["errors"][2], expected, rtol=0, atol=1e-9
    )
    with pytest.raises(ValueError, match=r"first_run: expected an integer in \[0, 2\*\*64 - 1\]"):
        sim.run_monte_carlo("K1", CASE, 1, 3, ["EKF"], steps=STEPS, first_run=-1)
    with pytest.raises(
        ValueError, match="first_run: expected first_run \\+ runs - 1 <= 2\\^64 - 1"
    ):
        sim.run_monte_carlo("K1", CASE, 2, 3, ["EKF"], steps=STEPS, first_run=2**64 - 1)


def test_summaries_and_the_k2_study_name_the_runs_of_a_chunk(full: dict) -> None:
    part = sim.run_monte_carlo("K1", CASE, 3, 3, ESTIMATORS, steps=STEPS, first_run=2)
    summary = sim.summarize("K1", part)
    assert summary.first_run == 2
    assert sim.format_table(summary).startswith(f"K1 case {CASE}: 3 runs (runs 2..4) x 110 steps")
    assert sim.summarize("K1", full).first_run == 0
    assert sim.format_table(sim.summarize("K1", full)).startswith(
        f"K1 case {CASE}: 6 runs x 110 steps"
    )
    # a result dict without first_run (written by hand) starts at run 0; a bad one is named
    legacy = {k: v for k, v in part.items() if k != "first_run"}
    assert sim.summarize("K1", legacy).first_run == 0
    with pytest.raises(ValueError, match=r"result\['first_run'\]: expected an int >= 0, got str"):
        sim.summarize("K1", {**part, "first_run": "2"})

    # K2: runs 1..2 alone average rows 1..2 of the runner's errors
    mc = sim.run_monte_carlo("K2", "alternating", 3, 5, ["EKF"], steps=250)
    tail = sim.run_k2_study(2, 5, 250, ["EKF"], first_run=1)
    assert tail.first_run == 1
    np.testing.assert_allclose(
        tail.estimators[0].position_error,
        mc["estimators"]["EKF"]["errors"][1:3].mean(axis=0),
        rtol=0,
        atol=1e-9,
    )
    assert sim.format_k2_study(tail).startswith("K2 study: 2 runs (runs 1..2) x 250 steps")
    with pytest.raises(
        ValueError, match="first_run: expected first_run \\+ runs - 1 <= 2\\^64 - 1"
    ):
        sim.run_k2_study(2, 5, 250, ["EKF"], first_run=2**64 - 1)
    with pytest.raises(ValueError, match=r"first_run: expected an integer in \[0, 2\*\*64 - 1\]"):
        sim.run_k2_study(sim.K2(), 1, 5, 250, ["EKF"], first_run=-1)


def test_merge_joins_consecutive_chunks_in_any_order(full: dict) -> None:
    chunks = [
        sim.run_monte_carlo("K1", CASE, n, 3, ESTIMATORS, steps=STEPS, first_run=f)
        for f, n in ((0, 2), (2, 1), (3, 3))
    ]
    merged = montecarlo.merge([chunks[2], chunks[0], chunks[1]])
    assert_same_runs(merged, full)
    assert merged["wall_seconds"] == pytest.approx(sum(c["wall_seconds"] for c in chunks))
    case_index = sim.scenario_info("K1")["cases"].index(CASE)
    assert merged["case_index"] == full["case_index"] == case_index
    # results saved before case_index existed still merge (and the merge leaves it out)
    older = [{k: v for k, v in c.items() if k != "case_index"} for c in chunks]
    assert "case_index" not in montecarlo.merge(older)
    assert_same_runs(montecarlo.merge(older), full)
    with pytest.raises(ValueError, match="expected at least one result"):
        montecarlo.merge([])
    with pytest.raises(ValueError, match="runs from 3 follow runs ending at 1"):
        montecarlo.merge([chunks[0], chunks[2]])
    with pytest.raises(ValueError, match="runs from 0 follow runs ending at 1"):
        montecarlo.merge([chunks[0], chunks[0]])
    other_seed = sim.run_monte_carlo("K1", CASE, 1, 4, ESTIMATORS, steps=STEPS, first_run=2)
    with pytest.raises(ValueError, match="seed differs between chunks"):
        montecarlo.merge([chunks[0], other_seed])
    ekf_only = sim.run_monte_carlo("K1", CASE, 1, 3, ["EKF"], steps=STEPS, first_run=2)
    with pytest.raises(ValueError, match="estimators differ between chunks"):
        montecarlo.merge([chunks[0], ekf_only])
    # not a result: named (it was an AttributeError or a KeyError from inside)
    with pytest.raises(
        TypeError, match=r"^results\[1\]: expected a dict of run_monte_carlo, got int$"
    ):
        montecarlo.merge([chunks[0], 3])
    broken = {k: v for k, v in chunks[1].items() if k != "discard"}
    with pytest.raises(ValueError, match=r"^results\[0\]: .* missing \['discard'\]$"):
        montecarlo.merge([broken, chunks[0]])


def test_an_executor_runs_the_chunks_and_gives_the_single_call_result(full: dict) -> None:
    done: list[int] = []
    ctx = multiprocessing.get_context("spawn")  # no fork of a process with threads
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as ex:
        res = montecarlo.run(
            "K1",
            CASE,
            6,
            3,
            ESTIMATORS,
            threads=1,
            steps=STEPS,
            progress=lambda d, t: done.append(d),
            executor=ex,
            chunk_runs=4,
        )
    assert_same_runs(res, full)
    assert sorted(done) == done and done[-1] == 6 and set(done) <= {2, 4, 6}
    with ThreadPoolExecutor(max_workers=2) as ex:  # a first_run and a default chunk size
        part = montecarlo.run(
            "K1", CASE, 3, 3, ESTIMATORS, steps=STEPS, progress=False, first_run=3, executor=ex
        )
    np.testing.assert_array_equal(
        part["estimators"]["noisy"]["errors"], full["estimators"]["noisy"]["errors"][3:]
    )


def test_a_dask_client_is_an_executor(full: dict) -> None:
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        res = montecarlo.run(
            "K1", CASE, 6, 3, ESTIMATORS, steps=STEPS, progress=False, executor=client, chunk_runs=2
        )
    assert_same_runs(res, full)


class Failing(NoisyTruth):
    def step(self, k: int, y: np.ndarray, o: np.ndarray) -> np.ndarray:
        raise RuntimeError("chunk failed on purpose")


def test_executor_arguments_and_failures() -> None:
    with ThreadPoolExecutor(max_workers=2) as ex:
        with pytest.raises(ValueError, match="case: unknown case 'nope' of scenario K3"):
            montecarlo.run(sim.K3(), "nope", 2, executor=ex, progress=False)
        with pytest.raises(ValueError, match="case: unknown case 'nope' of scenario K1"):
            montecarlo.run("K1", "nope", 2, executor=ex, progress=False)
        with pytest.raises(
            ValueError, match="estimators: unknown estimator 'nope' for scenario K1"
        ):
            montecarlo.run("K1", CASE, 2, estimators=["nope"], executor=ex, progress=False)
        with pytest.raises(ValueError, match="chunk_runs: expected an int >= 1, got 0"):
            montecarlo.run("K1", CASE, 2, executor=ex, chunk_runs=0, progress=False)
        with pytest.raises(ValueError, match="runs: expected an int >= 1, got 0"):
            montecarlo.run("K1", CASE, 0, executor=ex, progress=False)
        with pytest.raises(RuntimeError, match="chunk failed on purpose"):
            montecarlo.run(
                "K1", CASE, 4, 1, [("f", Failing)], steps=STEPS, executor=ex, progress=False
            )
        # numpy integers, as without an executor; first_run + runs beyond 2^64 before any chunk
        r = montecarlo.run(
            "K1",
            CASE,
            np.int64(2),
            1,
            ["EKF"],
            steps=STEPS,
            progress=False,
            executor=ex,
            first_run=np.uint64(1),
            chunk_runs=np.int32(1),
        )
        assert (r["runs"], r["first_run"]) == (2, 1)
        msg = (
            r"^first_run: expected first_run \+ runs - 1 <= 2\^64 - 1, "
            r"got first_run 18446744073709551615 and runs 2$"
        )
        with pytest.raises(ValueError, match=msg):
            montecarlo.run("K1", CASE, 2, first_run=2**64 - 1, executor=ex, progress=False)
        with pytest.raises(ValueError, match=r"^runs: expected an int >= 1, got 2.0$"):
            montecarlo.run("K1", CASE, 2.0, executor=ex, progress=False)
    with pytest.raises(TypeError, match="executor: expected an object with submit"):
        montecarlo.run("K1", CASE, 2, executor=object(), progress=False)
    # a single name was split into the estimators 'E', 'K', 'F'
    with pytest.raises(TypeError, match="^estimators: expected a list .* got a single string$"):
        montecarlo.run("K1", CASE, 1, 1, "EKF", steps=STEPS, progress=False)
    with pytest.raises(ValueError, match="chunk_runs: only with an executor"):
        montecarlo.run("K1", CASE, 2, chunk_runs=1, progress=False)


def fields(obj: object) -> dict:
    cls = type(obj)
    return {k: getattr(obj, k) for k in dir(cls) if isinstance(getattr(cls, k), property)}


def test_scenarios_and_their_parameters_pickle() -> None:
    h1, h2, k1, k2, k3 = (
        sim.H1Params(),
        sim.H2Params(),
        sim.K1Params(),
        sim.K2Params(),
        sim.K3Params(),
    )
    h1.speed, h1.start = 3.0, np.array([10.0, -20.0])
    h2.side, h2.pf_particles = 120.0, 500
    k1.sigma_los, k1.anchors = 4.0, k1.anchors + 10.0
    base = k2.base
    base.nlos_mean = 300.0
    k2.base, k2.period = base, 30
    k3.threshold = 2.5
    for params, make, case in (
        (h1, sim.H1, None),
        (h2, sim.H2, None),
        (k1, sim.K1, None),
        (k2, sim.K2, "alternating"),
        (k3, sim.K3, None),
    ):
        again = pickle.loads(pickle.dumps(params))
        assert type(again) is type(params)
        for key, value in fields(params).items():
            got = getattr(again, key)
            if isinstance(value, sim.K1Params):
                assert fields(got).keys() == fields(value).keys()
                for k, v in fields(value).items():
                    np.testing.assert_array_equal(getattr(got, k), v)
            else:
                np.testing.assert_array_equal(got, value, err_msg=key)
        scenario = make(params)
        copy = pickle.loads(pickle.dumps(scenario))
        assert type(copy) is type(scenario)
        c = case or scenario.cases[-1]
        a, b = scenario.draw(c, 5, 1, 30), copy.draw(c, 5, 1, 30)
        np.testing.assert_array_equal(a["y"], b["y"])
        np.testing.assert_array_equal(a["positions"], b["positions"])
    assert pickle.loads(pickle.dumps(k2)).base.nlos_mean == 300.0


def on_spawn_pool(scenario: sim.Scenario, entries: list) -> dict:
    """montecarlo.run of 4 runs from seed 3 in chunks of 2 on two spawned processes (every argument
    travels by pickle)."""
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as ex:
        return montecarlo.run(
            scenario,
            CASE,
            4,
            3,
            entries,
            threads=1,
            steps=STEPS,
            progress=False,
            executor=ex,
            chunk_runs=2,
        )


def test_an_executor_runs_a_scenario_with_custom_parameters() -> None:
    params = sim.K1Params()
    params.sigma_los = 4.0
    scenario = sim.K1(params)
    local = montecarlo.run(scenario, CASE, 4, 3, ESTIMATORS, steps=STEPS, progress=False)
    assert_same_runs(on_spawn_pool(scenario, ESTIMATORS), local)
    default = sim.run_monte_carlo("K1", CASE, 4, 3, ["EKF"], steps=STEPS)
    assert not np.array_equal(
        default["estimators"]["EKF"]["errors"], local["estimators"]["EKF"]["errors"]
    )


def same_fields(a, b) -> None:
    """Every read-write field of a equals b's, nested settings field by field."""
    assert type(a) is type(b)
    for key, value in fields(a).items():
        got = getattr(b, key)
        if fields(value):
            same_fields(value, got)
        elif isinstance(value, core.SigmaScheme):
            assert (got.kind, got.alpha, got.beta, got.kappa) == (
                value.kind,
                value.alpha,
                value.beta,
                value.kappa,
            )
        else:
            np.testing.assert_array_equal(got, value, err_msg=key)


def test_options_schemes_and_motion_models_pickle() -> None:
    r = rbpf.RbpfOptions()
    r.num_particles, r.merge_threshold, r.max_offspring = 33, 0.25, 2**40
    r.variant, r.scheme = rbpf.RbpfVariant.Classical, core.SigmaScheme.julier(1.5)
    p = rbpf.PfOptions()
    p.num_particles, p.seed, p.resampling = 777, 2**63 + 5, rbpf.PfResampling.Systematic
    q = mitigation.QpBiasEkfOptions()
    q.gamma, q.reference, q.soft_threshold = 1.3, mitigation.BiasReference.Snapshot, 0.5
    q.noise.sigma0, q.noise.relative = 7.5, 0.01
    b = mitigation.BiasAugmentedEkfOptions()
    b.iterations, b.noise.min_std = 4, 0.2
    qs = mitigation.BoxQpSettings()
    qs.eps_abs, qs.max_iter = 1e-7, 33
    g = snapshot.GaussNewtonOptions()
    g.max_iterations = 7
    ch, co, ur = snapshot.ChenOptions(), snapshot.CongOptions(), snapshot.UrruelaOptions()
    ch.reject_fraction, co.fit_seed, ur.p_nlos = 0.25, 99, 0.3
    layout = models.ConstantVelocityClock3.layout()
    for o in [r, p, q, b, qs, g, ch, co, ur, layout]:
        same_fields(o, pickle.loads(pickle.dumps(o)))
    for s in [
        core.SigmaScheme.scaled(0.5, 1.5, 0.25),
        core.SigmaScheme.julier(2.0),
        core.SigmaScheme.cubature(),
        core.SigmaScheme.huerta(0.7),
    ]:
        t = pickle.loads(pickle.dumps(s))
        assert (t.kind, t.alpha, t.beta, t.kappa) == (s.kind, s.alpha, s.beta, s.kappa)
    rn = pickle.loads(pickle.dumps(snapshot.RowNoise(1.0, 2.0, 3.0)))
    assert (rn.center, rn.sigma_left, rn.sigma_right) == (1.0, 2.0, 3.0)
    for m in [
        models.ConstantVelocity2(0.1, 2.0, models.VelocityNoise.WhiteAcceleration),
        models.ConstantVelocity3(0.2, 1.0),
        models.ConstantVelocityClock2(0.01, 1.0, 0.5),
        models.ConstantVelocityClock3(0.02, 3.0, 0.25),
        models.TwoWayClock(0.5, 1e-6, 1e-7, 0.3),
    ]:
        n = pickle.loads(pickle.dumps(m))
        assert type(n) is type(m) and n.dt == m.dt
        np.testing.assert_array_equal(n.F, m.F)
        np.testing.assert_array_equal(n.Q, m.Q)


class QpFactory:
    """Builds K1's proposed tracker with options it holds (they pickle with it)."""

    def __init__(self, options: mitigation.QpBiasEkfOptions) -> None:
        self.options = options

    def __call__(self, scenario: sim.Scenario, case_index: int) -> mitigation.QpBiasEkf:
        return mitigation.QpBiasEkf(
            scenario.motion, scenario.params.anchors, np.zeros(4), np.eye(4), self.options
        )


def test_an_executor_runs_a_factory_that_holds_options() -> None:
    k1 = sim.K1()
    o = mitigation.QpBiasEkfOptions()
    o.gamma, o.noise.sigma0 = k1.params.gamma, k1.params.sigma_los
    it = mitigation.BiasAugmentedEkfOptions()
    it.noise.sigma0 = k1.params.sigma_los
    it.bias_prior_std = k1.params.iterated_bias_prior_std
    it.bias_walk_std = k1.params.iterated_bias_walk_std
    it.iterations = k1.params.iterated_iterations
    m, c = np.zeros(4), np.eye(4)
    entries = [
        "proposed",
        "iterated-NLOS-EKF",
        ("mine", QpFactory(o)),
        # the trackers themselves travel too (they pickle), each with a solver of its own kind
        ("object", mitigation.QpBiasEkf(k1.motion, k1.params.anchors, m, c, o, "enumeration")),
        ("iterated-object", mitigation.BiasAugmentedEkf(k1.motion, k1.params.anchors, m, c, it)),
    ]
    local = montecarlo.run(k1, CASE, 4, 3, entries, steps=STEPS, progress=False)
    e = {k: v["errors"] for k, v in local["estimators"].items()}
    np.testing.assert_array_equal(e["mine"], e["proposed"])
    np.testing.assert_array_equal(e["object"], e["proposed"])
    np.testing.assert_array_equal(e["iterated-object"], e["iterated-NLOS-EKF"])
    assert_same_runs(on_spawn_pool(k1, entries), local)


def test_an_rbpf_and_a_pf_object_travel_to_spawned_workers() -> None:
    h1 = sim.H1()
    o = rbpf.RbpfOptions()
    o.variant = rbpf.RbpfVariant.Reordered
    o.num_particles = h1.params.rbpf_particles
    q = situation.QualityModel(h1.quality)
    mine = rbpf.Rbpf(h1.motion, h1.measurements, h1.sight_process, q, np.zeros(4), np.eye(4), o)
    po = rbpf.PfOptions(num_particles=500, seed=9)
    args = (h1.motion, h1.measurements, h1.sight_process, q, np.zeros(4), np.eye(4))
    pf = rbpf.ParticleFilter(*args, po)
    entries = ["rRBPF-8", ("mine", mine), ("pf", pf)]
    local = montecarlo.run(h1, "default", 4, 3, entries, steps=120, progress=False)
    np.testing.assert_array_equal(
        local["estimators"]["mine"]["errors"], local["estimators"]["rRBPF-8"]["errors"]
    )
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as ex:
        remote = montecarlo.run(
            h1,
            "default",
            4,
            3,
            entries,
            threads=1,
            steps=120,
            progress=False,
            executor=ex,
            chunk_runs=2,
        )
    assert_same_runs(remote, local)
