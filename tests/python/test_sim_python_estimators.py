"""Estimators written in Python in the Monte Carlo runner: run_monte_carlo's (name, factory)."""

from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from nlosloc import core, filters, models, montecarlo, noise, sim


class PythonEkf:
    """K1's registered "EKF" (k1.hpp make_k1_ekf) rebuilt from the Python filter classes."""

    def __init__(self, scenario: sim.Scenario, case_index: int) -> None:
        self.case_index = case_index
        self.f = filters.Ekf(scenario.motion, scenario.measurements, np.zeros(4), np.eye(4))

    def reset(self, draw: dict, rng: core.Rng) -> None:
        self.f.set_belief(draw["initial_mean"], draw["initial_cov"], 0.0)

    def step(self, k: int, y: np.ndarray, o: np.ndarray) -> np.ndarray:
        if k > 0:
            self.f.step(y)
        else:
            self.f.update(y)  # the initial belief is already at t_0, as the registered one does
        return self.f.mean[:2]


class Oracle:
    """Returns the true position plus `offset` and checks that step k gets the draw's row k."""

    def __init__(self, offset: tuple[float, float] = (0.0, 0.0), noise: float = 0.0) -> None:
        self.offset = np.asarray(offset)
        self.noise = noise

    def reset(self, draw: dict, rng: core.Rng) -> None:
        self.draw = draw
        self.rng = rng

    def step(self, k: int, y: np.ndarray, o: np.ndarray) -> np.ndarray:
        np.testing.assert_array_equal(y, self.draw["y"][k])
        np.testing.assert_array_equal(o, self.draw["quality"][k])
        p = self.draw["positions"][k] + self.offset
        if self.noise:
            p = p + self.noise * np.array([self.rng.normal(), 0.0])
        return p


class SightOracle(Oracle):
    def step(self, k: int, y: np.ndarray, o: np.ndarray) -> np.ndarray:
        self.k = k
        return super().step(k, y, o)

    def sight_estimate(self) -> np.ndarray:
        return self.draw["sight"][self.k]


class AllLos(Oracle):
    def sight_estimate(self) -> list[int]:
        return [0, 0, 0]


def oracle(*args: object, **kwargs: object):
    return lambda scenario, case_index: Oracle(*args, **kwargs)


def test_a_python_estimator_reproduces_the_registered_one() -> None:
    case = "2LOS/1NLOS"
    res = sim.run_monte_carlo(
        "K1", case, 4, 7, ["EKF", ("py-EKF", PythonEkf)], threads=2, steps=110
    )
    ours = res["estimators"]["py-EKF"]["errors"]
    np.testing.assert_allclose(ours, res["estimators"]["EKF"]["errors"], rtol=0, atol=1e-9)
    assert ours.shape == (4, 110) and np.all(ours > 0)
    # the same through the scenario-object overload and nlosloc.montecarlo.run
    alone = sim.run_monte_carlo(sim.K1(), case, 4, 7, [("py-EKF", PythonEkf)], steps=110)
    np.testing.assert_array_equal(alone["estimators"]["py-EKF"]["errors"], ours)
    done: list[int] = []
    wrapped = montecarlo.run(
        "K1",
        case,
        4,
        7,
        [("py-EKF", PythonEkf)],
        threads=2,
        steps=110,
        progress=lambda d, t: done.append(d),
    )
    assert done[-1] == 4
    np.testing.assert_array_equal(wrapped["estimators"]["py-EKF"]["errors"], ours)


def test_factory_gets_the_callers_scenario_and_the_case_index() -> None:
    params = sim.K1Params()
    params.sigma_los = 4.0
    scenario = sim.K1(params)
    seen = []

    def factory(s: sim.Scenario, c: int) -> Oracle:
        seen.append((s, c))
        return Oracle()

    sim.run_monte_carlo(scenario, "0LOS/3NLOS", 2, 1, [("o", factory)], threads=1, steps=105)
    assert len(seen) == 1
    assert seen[0][0] is scenario and seen[0][0].params.sigma_los == 4.0
    assert seen[0][1] == scenario.case_index("0LOS/3NLOS") == 3


def test_errors_are_the_distance_to_what_step_returns() -> None:
    res = sim.run_monte_carlo(
        "K1", "3LOS/0NLOS", 3, 2, [("exact", oracle()), ("off", oracle((3.0, -4.0)))], steps=110
    )
    np.testing.assert_array_equal(res["estimators"]["exact"]["errors"], np.zeros((3, 110)))
    np.testing.assert_allclose(res["estimators"]["off"]["errors"], 5.0, rtol=0, atol=1e-9)
    assert np.all(res["estimators"]["exact"]["time_per_step_ns"] > 0)
    assert "sight_accuracy" not in res["estimators"]["exact"]


def test_rng_is_the_estimators_own_stream_and_threads_do_not_matter() -> None:
    seed, runs, steps = 11, 5, 104
    results = [
        sim.run_monte_carlo(
            "K1", "3LOS/0NLOS", runs, seed, [("noisy", oracle(noise=2.0))], threads=t, steps=steps
        )["estimators"]["noisy"]["errors"]
        for t in (1, 2)
    ]
    np.testing.assert_array_equal(results[0], results[1])
    for r in range(runs):
        rng = core.Rng(sim.estimator_seed(seed, "noisy"), r)
        expected = [abs(2.0 * rng.normal()) for _ in range(steps)]
        np.testing.assert_allclose(results[0][r], expected, rtol=0, atol=1e-9)


def test_sight_estimate_is_scored_against_the_true_sight() -> None:
    res = sim.run_monte_carlo(
        "K1",
        "2LOS/1NLOS",
        2,
        3,
        [("sight", lambda s, c: SightOracle()), ("los", lambda s, c: AllLos())],
        steps=110,
    )
    np.testing.assert_array_equal(res["estimators"]["sight"]["sight_accuracy"], np.ones((2, 110)))
    np.testing.assert_array_equal(
        res["estimators"]["sight"]["sight_anchor_accuracy"], np.ones((2, 3))
    )
    # K1's 2LOS/1NLOS: the third node NLOS for the whole run, the others LOS
    np.testing.assert_allclose(
        res["estimators"]["los"]["sight_accuracy"], 2.0 / 3.0, rtol=0, atol=1e-12
    )
    np.testing.assert_array_equal(
        res["estimators"]["los"]["sight_anchor_accuracy"], np.tile([1.0, 1.0, 0.0], (2, 1))
    )


def test_malformed_estimators_are_refused() -> None:
    run = sim.run_monte_carlo
    with pytest.raises(TypeError, match="estimators: expected a list .* got a single string"):
        run("K1", "3LOS/0NLOS", 1, 1, "EKF")
    with pytest.raises(TypeError, match=r"estimators\[1\]: expected a registered estimator name"):
        run("K1", "3LOS/0NLOS", 1, 1, ["EKF", ("x", 3)])
    with pytest.raises(TypeError, match=r"estimators\[0\]: expected .* got 42"):
        run("K1", "3LOS/0NLOS", 1, 1, [42])
    with pytest.raises(ValueError, match="unknown estimator 'nope' for scenario K1"):
        run("K1", "3LOS/0NLOS", 1, 1, [("o", oracle()), "nope"])
    with pytest.raises(ValueError, match="estimators: 'EKF' appears more than once"):
        run("K1", "3LOS/0NLOS", 1, 1, ["EKF", ("EKF", oracle())])


def test_a_python_estimator_that_misbehaves_stops_the_run_with_a_clear_error() -> None:
    def run(factory, **kw):
        return sim.run_monte_carlo("K1", "3LOS/0NLOS", 3, 1, [("bad", factory)], steps=105, **kw)

    with pytest.raises(TypeError, match="factory of 'bad' returned None"):
        run(lambda s, c: None)
    with pytest.raises(
        TypeError,
        match="factory of 'bad' returned an object of type int, which has no "
        r"method reset\(draw, rng\)",
    ):
        run(lambda s, c: 5)

    class NoStep:
        def reset(self, draw, rng):
            pass

    with pytest.raises(TypeError, match=r"has no method step\(k, y, o\)"):
        run(lambda s, c: NoStep())

    class Wrong(Oracle):
        def step(self, k, y, o):
            return np.zeros(3)

    with pytest.raises(
        ValueError,
        match=r"step\(\) of 'bad' returned an array of shape \(3,\); "
        "expected the 2 coordinates of the position",
    ):
        run(lambda s, c: Wrong(), threads=2)

    class Nothing(Oracle):
        def step(self, k, y, o):
            return None

    with pytest.raises(
        ValueError,
        match=r"type NoneType, read as an array of shape \(\); expected the 2 coordinates",
    ):
        run(lambda s, c: Nothing())

    class Boom(Oracle):
        def step(self, k, y, o):
            if k == 3:
                raise KeyError("boom at step 3")
            return super().step(k, y, o)

    with pytest.raises(KeyError, match="boom at step 3"):
        run(lambda s, c: Boom(), threads=2)

    class FloatSight(Oracle):
        def sight_estimate(self):
            return np.zeros(3)

    with pytest.raises(
        ValueError,
        match=r"sight_estimate\(\) of 'bad' returned an array of shape \(3,\); "
        "expected 3 integer conditions",
    ):
        run(lambda s, c: FloatSight())

    class ShortSight(Oracle):
        def sight_estimate(self):
            return [0, 1]

    with pytest.raises(
        ValueError, match=r"returned an object of type list, read as an array of shape \(2,\)"
    ):
        run(lambda s, c: ShortSight())

    class NegativeSight(Oracle):
        def sight_estimate(self):
            return [0, -1, 0]

    with pytest.raises(ValueError, match="returned condition -1 for anchor 1"):
        run(lambda s, c: NegativeSight())

    class UnknownCondition(Oracle):  # K1 has 2 conditions; 7 was scored as a wrong guess
        def sight_estimate(self):
            return [0, 7, 0]

    with pytest.raises(
        ValueError, match=r"returned condition 7 for anchor 1; expected an integer in \[0, 2\)"
    ):
        run(lambda s, c: UnknownCondition())

    def factory_raises(s, c):
        raise RuntimeError("no estimator for you")

    with pytest.raises(RuntimeError, match="no estimator for you"):
        run(factory_raises, threads=2)


def test_k2_study_of_a_custom_k2_with_python_estimators() -> None:
    params = sim.K2Params()
    params.period = 50
    base = params.base
    base.discard = 20
    params.base = base
    scenario = sim.K2(params)
    runs, seed, steps = 3, 5, 160
    named = [("py-EKF", PythonEkf), ("sight", lambda s, c: SightOracle())]
    st = sim.run_k2_study(scenario, runs, seed, steps, ["EKF", *named])
    assert (st.period, st.discard, st.steps) == (50, 20, steps)
    np.testing.assert_array_equal(st.nlos, (np.arange(steps) // 50 + 1) % 2)
    ekf, py_ekf, sight = st.estimators
    assert (ekf.name, py_ekf.name, sight.name) == ("EKF", "py-EKF", "sight")
    np.testing.assert_allclose(py_ekf.position_error, ekf.position_error, rtol=0, atol=1e-9)
    mc = sim.run_monte_carlo(scenario, "alternating", runs, seed, ["EKF"], steps=steps)
    mean = mc["estimators"]["EKF"]["errors"].mean(axis=0)
    np.testing.assert_allclose(ekf.position_error, mean, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(sight.position_error, np.zeros(steps))
    np.testing.assert_array_equal(sight.identification, np.ones(steps))
    assert ekf.identification is None  # the EKF does not classify sight
    # the registered K2 (period 200) through the overload without a scenario
    assert sim.run_k2_study(1, seed, 250, [("sight", lambda s, c: SightOracle())]).period == 200
    with pytest.raises(TypeError, match=r"estimators\[0\]: expected a registered estimator name"):
        sim.run_k2_study(scenario, 1, 1, 30, [("x", None)])
    with pytest.raises(ValueError, match="estimators: 'EKF' appears more than once"):
        sim.run_k2_study(1, 1, 30, ["EKF", ("EKF", PythonEkf)])


def k1_filter(kind: str, scenario: sim.Scenario | None = None):
    s = scenario or sim.K1()
    make = {"ekf": filters.Ekf, "ukf": filters.Ukf, "ukf-aug": filters.UkfAugmented}[kind]
    return make(s.motion, s.measurements, np.zeros(4), np.eye(4))


def test_a_filter_object_runs_natively_as_an_estimator() -> None:
    ekf = k1_filter("ekf")
    res = sim.run_monte_carlo(
        "K1",
        "2LOS/1NLOS",
        4,
        7,
        [
            "EKF",
            ("native-EKF", ekf),
            ("oracle-EKF", k1_filter("ekf"), "oracle"),
            ("UKF", k1_filter("ukf")),
            ["UKF-aug", k1_filter("ukf-aug"), "assume_los"],
        ],
        threads=2,
        steps=300,
    )
    e = {k: v["errors"] for k, v in res["estimators"].items()}
    # the same C++ filter as the registered EKF: equal bit for bit
    np.testing.assert_array_equal(e["native-EKF"], e["EKF"])
    # a copy ran: the object keeps its belief
    np.testing.assert_array_equal(ekf.mean, np.zeros(4))
    assert ekf.time == 0.0
    # knowing the NLOS node's noise (mean 513 m) removes most of the EKF's error
    k = res["discard"]
    assert np.median(e["oracle-EKF"][:, k:]) < 0.3 * np.median(e["EKF"][:, k:])
    # the UKFs run the same model (no native estimator gives the same numbers to compare with)
    assert np.all(np.isfinite(e["UKF"])) and np.all(np.isfinite(e["UKF-aug"]))
    assert not np.array_equal(e["UKF"], e["EKF"])
    assert 0.5 < np.median(e["UKF"][:, k:]) / np.median(e["EKF"][:, k:]) < 2.0
    assert "sight_accuracy" not in res["estimators"]["native-EKF"]
    # through the K2 study too
    st = sim.run_k2_study(2, 1, 150, ["EKF", ("native-EKF", k1_filter("ekf"))])
    np.testing.assert_array_equal(st.estimators[1].position_error, st.estimators[0].position_error)


def test_a_filter_that_does_not_fit_the_scenario_is_refused() -> None:
    run = sim.run_monte_carlo
    case = "3LOS/0NLOS"
    k1 = sim.K1()
    with pytest.raises(
        ValueError, match="the filter of 'f' has a state of 6 components; scenario K1 has 4"
    ):
        motion3 = models.ConstantVelocity3(0.1, 1.0, models.VelocityNoise.WhiteAcceleration)
        meas3 = models.MeasurementStack(
            models.ConstantVelocity3.layout(), np.zeros((1, 3)) + 1.0, 2
        )
        meas3.add_toa(0, [noise.Normal(0.0, 1.0), noise.Normal(0.0, 2.0)])
        run("K1", case, 1, 1, [("f", filters.Ekf(motion3, meas3, np.zeros(6), np.eye(6)))])
    two_rows = models.MeasurementStack(models.ConstantVelocity2.layout(), k1.anchors[:2], 2)
    for b in range(2):
        two_rows.add_toa(b, [noise.Normal(0.0, 50.0), noise.Normal(0.0, 60.0)])
    with pytest.raises(ValueError, match="has 2 measurement rows; scenario K1 has 3"):
        run("K1", case, 1, 1, [("f", filters.Ekf(k1.motion, two_rows, np.zeros(4), np.eye(4)))])
    slow = models.ConstantVelocity2(0.5, 1.0, models.VelocityNoise.WhiteAcceleration)
    with pytest.raises(
        ValueError, match=r"predicts over dt = 0.5 s; scenario K1 samples every 0.1 s"
    ):
        run("K1", case, 1, 1, [("f", filters.Ukf(slow, k1.measurements, np.zeros(4), np.eye(4)))])
    with pytest.raises(
        ValueError, match=r"estimators\[0\]: expected the sight policy .* got 'truth'"
    ):
        run("K1", case, 1, 1, [("f", k1_filter("ekf"), "truth")])
    with pytest.raises(
        TypeError,
        match="returned a Python estimator; a sight policy goes with an Ekf, Ukf or UkfAugmented",
    ):
        run("K1", case, 1, 1, [("f", PythonEkf, "oracle")], steps=105)


def make_k1_ekf(scenario: sim.Scenario, case_index: int) -> filters.Ekf:
    """A factory that returns a filter (module level: it pickles, where the filter does not)."""
    return filters.Ekf(scenario.motion, scenario.measurements, np.zeros(4), np.eye(4))


def test_a_factory_that_returns_a_filter_runs_it_natively() -> None:
    entries = ["EKF", ("made", make_k1_ekf), ("made-oracle", make_k1_ekf, "oracle")]
    res = sim.run_monte_carlo("K1", "2LOS/1NLOS", 4, 7, entries, threads=2, steps=300)
    e = {k: v["errors"] for k, v in res["estimators"].items()}
    np.testing.assert_array_equal(e["made"], e["EKF"])
    oracle = sim.run_monte_carlo(
        "K1", "2LOS/1NLOS", 4, 7, [("o", k1_filter("ekf"), "oracle")], steps=300
    )
    np.testing.assert_array_equal(e["made-oracle"], oracle["estimators"]["o"]["errors"])
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as ex:
        remote = montecarlo.run(
            "K1",
            "2LOS/1NLOS",
            4,
            7,
            entries[1:],
            threads=1,
            steps=300,
            progress=False,
            executor=ex,
            chunk_runs=2,
        )
    np.testing.assert_array_equal(remote["estimators"]["made"]["errors"], e["made"])
    np.testing.assert_array_equal(remote["estimators"]["made-oracle"]["errors"], e["made-oracle"])
    slow = models.ConstantVelocity2(0.5, 1.0, models.VelocityNoise.WhiteAcceleration)
    with pytest.raises(ValueError, match=r"the filter of 'bad' predicts over dt = 0.5 s"):
        sim.run_monte_carlo(
            "K1",
            "2LOS/1NLOS",
            2,
            1,
            [("bad", lambda s, c: filters.Ekf(slow, s.measurements, np.zeros(4), np.eye(4)))],
            threads=2,
            steps=105,
        )
