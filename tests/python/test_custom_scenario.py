"""sim.CustomScenario: a scenario defined in Python, through draws, the runner and the tables."""

from __future__ import annotations

import numpy as np
import pytest

from nlosloc import core, filters, models, montecarlo, noise, sim

DT = 0.5
ANCHORS = np.array([[0.0, 0.0], [400.0, 0.0], [0.0, 400.0]])
MOTION = models.ConstantVelocity2(DT, 0.01, models.VelocityNoise.WhiteAcceleration)
BIAS = 80.0  # the NLOS range bias of anchor 0 in case "biased"


def stack() -> models.MeasurementStack:
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), ANCHORS, 2)
    for b in range(3):
        st.add_toa(b, [noise.Normal(0.0, 2.0), noise.Normal(BIAS, 2.0)])
    return st


def generate(case_index: int, steps: int, rng: core.Rng) -> dict:
    """A straight walk at (1, 0.5) m/s from (100, 100); anchor 0 NLOS in case 1."""
    t = np.arange(steps) * DT
    start = np.array([100.0, 100.0]) + np.array([rng.normal(), rng.normal()])
    pos = start + np.outer(t, [1.0, 0.5])
    states = np.hstack([pos, np.tile([1.0, 0.5], (steps, 1))])
    sight = np.zeros((steps, 3), dtype=int)
    sight[:, 0] = case_index
    dist = np.linalg.norm(pos[:, None, :] - ANCHORS[None, :, :], axis=2)
    y = (
        dist
        + 2.0 * np.array([[rng.normal() for _ in range(3)] for _ in range(steps)])
        + BIAS * sight
    )
    y[3, 1] = np.nan  # a missing range
    return {
        "states": states,
        "positions": pos,
        "y": y,
        "sight": sight,
        "initial_mean": np.array([100.0, 100.0, 1.0, 0.5]),
        "initial_cov": np.diag([4.0, 4.0, 0.25, 0.25]),
    }


def scenario(gen=generate, **kw) -> sim.CustomScenario:
    args = dict(name="walk", measurements=stack(), cases=["clean", "biased"], steps=60, dt=DT)
    args.update(kw)
    return sim.CustomScenario(generate=gen, **args)


class Truth:
    def reset(self, draw: dict, rng: core.Rng) -> None:
        self.positions = draw["positions"]

    def step(self, k: int, y: np.ndarray, o: np.ndarray) -> np.ndarray:
        return self.positions[k]


def ekf() -> filters.Ekf:
    return filters.Ekf(MOTION, stack(), np.zeros(4), np.eye(4))


def test_draws_are_what_generate_returns() -> None:
    s = scenario(discard=10, description="a walk", choices=["bias 80 m"])
    assert (s.name, s.cases, s.steps, s.dt, s.discard) == ("walk", ["clean", "biased"], 60, DT, 10)
    assert (s.description, s.choices, s.state_dim, s.space_dim) == ("a walk", ["bias 80 m"], 4, 2)
    np.testing.assert_array_equal(s.anchors, ANCHORS)
    d = s.draw("biased", 3, 2)
    expected = generate(1, 60, core.Rng(3, 2))
    for key in ("states", "positions", "y", "sight", "initial_mean", "initial_cov"):
        np.testing.assert_array_equal(d[key], expected[key], err_msg=key)
    assert np.isnan(d["quality"]).all() and d["quality"].shape == (60, 3)
    assert np.isnan(d["y"][3, 1])
    assert s.draw("biased", 3, 2, steps=20)["y"].shape == (20, 3)


def test_the_runner_and_the_tables_on_a_custom_scenario() -> None:
    s = scenario()
    estimators = [("truth", lambda sc, c: Truth()), ("EKF", ekf()), ("oracle", ekf(), "oracle")]
    runs = [
        sim.run_monte_carlo(s, "biased", 6, 1, estimators, threads=t)["estimators"] for t in (1, 2)
    ]
    for name in ("truth", "EKF", "oracle"):
        np.testing.assert_array_equal(runs[0][name]["errors"], runs[1][name]["errors"])
    e = {k: v["errors"] for k, v in runs[0].items()}
    np.testing.assert_array_equal(e["truth"], np.zeros((6, 60)))
    # knowing anchor 0's 80 m bias, the EKF tracks to a few metres; assuming LOS it does not
    assert np.median(e["oracle"][:, 20:]) < 5.0 < 20.0 < np.median(e["EKF"][:, 20:])
    res = montecarlo.run(s, "clean", 4, 1, estimators, progress=False)
    table = sim.format_table(sim.summarize(s, res))
    assert "walk case clean: 4 runs x 60 steps" in table and "oracle" in table


def test_custom_scenarios_are_checked() -> None:
    with pytest.raises(ValueError, match="name: 'K1' is a built-in scenario"):
        scenario(name="K1")
    with pytest.raises(ValueError, match="cases: expected distinct case names"):
        scenario(cases=["a", "a"])
    with pytest.raises(ValueError, match="cases: expected at least one case name"):
        scenario(cases=[])
    with pytest.raises(ValueError, match="discard: expected 0 <= discard < steps, got 60"):
        scenario(discard=60)
    with pytest.raises(ValueError, match="dt: expected a finite period > 0"):
        scenario(dt=0.0)
    with pytest.raises(TypeError, match="generate: expected a callable"):
        scenario(gen=3)
    s = scenario()
    with pytest.raises(
        ValueError, match="scenario 'walk' has no registered estimators; give Python"
    ):
        sim.run_monte_carlo(s, "clean", 1, 1)
    with pytest.raises(
        ValueError, match=r"estimators\[0\]: scenario 'walk' has no registered estimators"
    ):
        sim.run_monte_carlo(s, "clean", 1, 1, ["EKF"])


def broken(**change):
    def gen(c: int, steps: int, rng: core.Rng) -> dict:
        d = generate(c, steps, rng)
        for k, v in change.items():
            if v is None:
                del d[k]
            else:
                d[k] = v(d) if callable(v) else v
        return d

    return scenario(gen=gen)


def test_what_generate_returns_is_checked() -> None:
    cases = [
        (dict(y=None), ValueError, "generate: 'y': missing"),
        (dict(y=lambda d: d["y"][:, :2]), ValueError, r"'y': expected an array of shape \(60, 3\)"),
        (dict(y=lambda d: d["y"] + np.inf), ValueError, r"'y': expected finite values or NaN"),
        (
            dict(quality=lambda d: np.full((60, 3), np.inf)),  # it was let through
            ValueError,
            r"^generate: 'quality': expected finite values or NaN \(missing\), got inf at \(0, 0\)",
        ),
        (
            dict(sight=lambda d: d["sight"] + 2),
            ValueError,
            r"'sight': expected conditions in \[0, 2\)",
        ),
        (dict(sight=lambda d: d["sight"] + 0.5), ValueError, "'sight': expected integers"),
        (dict(initial_cov=-np.eye(4)), ValueError, "symmetric positive definite"),
        (dict(initial_mean=np.zeros(3)), ValueError, "generate: 'initial_mean': expected shape"),
        (dict(states=lambda d: d["states"] * np.nan), ValueError, "expected finite values"),
    ]
    for change, error, message in cases:
        with pytest.raises(error, match=message):
            broken(**change).draw("clean", 1, 0)
    with pytest.raises(
        TypeError, match="generate: expected a dict of arrays, got an object of type list"
    ):
        scenario(gen=lambda c, t, r: []).draw("clean", 1, 0)
    with pytest.raises(ZeroDivisionError):
        scenario(gen=lambda c, t, r: 1 / 0).draw("clean", 1, 0)
    # from the runner's worker threads too
    with pytest.raises(ValueError, match="generate: 'y': missing"):
        sim.run_monte_carlo(broken(y=None), "clean", 4, 1, [("EKF", ekf())], threads=2)


def test_backdate_is_undone_by_one_prediction() -> None:
    mean, cov = np.array([100.0, 50.0, 1.0, -0.5]), np.diag([4.0, 9.0, 0.3, 0.2])
    m0, P0 = sim.backdate(MOTION, mean, cov)
    f = filters.Ekf(MOTION, stack(), m0, P0)
    f.predict()
    np.testing.assert_allclose(f.mean, mean, atol=1e-12)
    np.testing.assert_allclose(f.cov, cov, atol=1e-12)
    assert not np.allclose(m0, mean)
    # P - Q not positive definite: the belief itself
    tiny = np.eye(4) * 1e-12
    m1, P1 = sim.backdate(MOTION, mean, tiny)
    np.testing.assert_array_equal(m1, mean)
    np.testing.assert_array_equal(P1, tiny)
    with pytest.raises(ValueError, match="cov: expected shape"):
        sim.backdate(MOTION, mean, np.eye(3))
