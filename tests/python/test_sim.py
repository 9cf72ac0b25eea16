"""nlosloc.sim bindings and the montecarlo / plots helpers."""

from __future__ import annotations

import os

import numpy as np
import pytest

from nlosloc import montecarlo, sim

CASE = "2LOS/1NLOS"


def test_registry_and_info() -> None:
    assert "K1" in sim.scenarios()
    info = sim.scenario_info("K1")
    assert info["cases"] == ["3LOS/0NLOS", "2LOS/1NLOS", "1LOS/2NLOS", "0LOS/3NLOS"]
    assert "EKF" in info["estimators"]
    assert info["steps"] == 2000 and info["discard"] == 100 and info["dt"] == pytest.approx(0.1)
    assert info["anchors"].shape == (3, 2)
    assert any("1000, 1000" in c for c in info["choices"])
    table = {(v["estimator"], v["case"], v["metric"]): v["value"] for v in info["paper"]}
    assert table[("EKF", "2LOS/1NLOS", "p67")] == pytest.approx(309.2)
    assert table[("proposed", "0LOS/3NLOS", "p95")] == pytest.approx(76.58)
    with pytest.raises(ValueError, match="K1"):
        sim.scenario_info("K9")


def test_the_registered_scenario_object() -> None:
    for name in sim.scenarios():
        s = sim.scenario(name)
        assert type(s).__name__ == name and s.name == name  # its own class, not the base
        info = sim.scenario_info(name)
        assert s.cases == info["cases"] and s.steps == info["steps"]
    k1 = sim.scenario("K1")
    by_name = sim.draw("K1", CASE, seed=3, run=2, steps=20)
    np.testing.assert_array_equal(k1.draw(CASE, seed=3, run=2, steps=20)["y"], by_name["y"])
    with pytest.raises(ValueError, match="K1"):
        sim.scenario("K9")


def test_draw_reproducible() -> None:
    a = sim.draw("K1", CASE, seed=3, run=2)
    b = sim.draw("K1", CASE, seed=3, run=2)
    c = sim.draw("K1", CASE, seed=3, run=5)
    assert a["states"].shape == (2000, 4)
    assert a["positions"].shape == (2000, 2)
    assert a["y"].shape == (2000, 3)
    assert a["sight"].shape == (2000, 3) and np.issubdtype(a["sight"].dtype, np.integer)
    assert np.all(np.isnan(a["quality"]))
    assert a["initial_mean"].shape == (4,) and a["initial_cov"].shape == (4, 4)
    for key in ("states", "y", "sight", "initial_mean"):
        np.testing.assert_array_equal(a[key], b[key])
    assert not np.any(a["y"] == c["y"])
    np.testing.assert_array_equal(a["sight"][:, 2], 1)  # last node NLOS
    short = sim.draw("K1", CASE, seed=3, run=2, steps=50)
    np.testing.assert_array_equal(short["y"], a["y"][:50])
    with pytest.raises(ValueError, match="3LOS/0NLOS"):
        sim.draw("K1", "nope", seed=1, run=0)
    cases = sim.scenario_info("K1")["cases"]
    assert cases[a["case_index"]] == a["case"] == CASE and a["case_index"] != 0
    assert sim.draw("K1", cases[0], seed=3, run=2, steps=5)["case_index"] == 0


def test_run_monte_carlo_shapes_and_threads() -> None:
    r1 = sim.run_monte_carlo("K1", CASE, runs=4, seed=1, threads=1, steps=300)
    r2 = sim.run_monte_carlo("K1", CASE, runs=4, seed=1, threads=2, steps=300, estimators=["EKF"])
    assert r1["discard"] == 100 and r1["dt"] == pytest.approx(0.1) and r1["steps"] == 300
    assert r1["case"] == CASE and sim.scenario_info("K1")["cases"][r1["case_index"]] == CASE
    e = r1["estimators"]["EKF"]
    assert e["errors"].shape == (4, 300)
    assert e["time_per_step_ns"].shape == (4,)
    assert np.all(e["time_per_step_ns"] > 0)
    np.testing.assert_array_equal(e["errors"], r2["estimators"]["EKF"]["errors"])
    with pytest.raises(ValueError, match="EKF"):
        sim.run_monte_carlo("K1", CASE, runs=2, seed=1, estimators=["UKF"])
    with pytest.raises(ValueError):
        sim.run_monte_carlo("K1", CASE, runs=0, seed=1)


def test_percentiles_match_numpy() -> None:
    res = montecarlo.run("K1", CASE, runs=3, seed=2, steps=400, progress=False)
    errors = res["estimators"]["EKF"]["errors"]
    pooled = errors[:, 100:].ravel()
    q = [50, 67, 90, 95]
    got = montecarlo.percentiles(res, q)["EKF"]
    np.testing.assert_array_equal(got, np.percentile(pooled, q))
    # The C++ metric used by the bench agrees with numpy to the last bit or so.
    np.testing.assert_allclose(sim.percentiles(pooled, q), np.percentile(pooled, q), rtol=1e-15)
    x, p = montecarlo.ecdf(pooled)
    np.testing.assert_array_equal(x, np.sort(pooled))
    assert p[-1] == 1.0 and p[0] == pytest.approx(1 / pooled.size)
    cx, cp = sim.ecdf(pooled)
    np.testing.assert_array_equal(cx, x)
    np.testing.assert_allclose(cp, p, rtol=1e-15)
    np.testing.assert_allclose(
        sim.rmse_over_time(errors), np.sqrt(np.mean(errors**2, axis=0)), rtol=1e-14
    )
    np.testing.assert_allclose(montecarlo.rmse(res)["EKF"], sim.rmse_over_time(errors), rtol=1e-14)
    assert sim.probability_within(np.array([1.0, 2.0, 3.0, 4.0]), 2.0) == 0.5


def test_progress_callback_called() -> None:
    calls: list[tuple[int, int]] = []
    montecarlo.run(
        "K1", CASE, runs=5, seed=1, steps=150, progress=lambda d, t: calls.append((d, t))
    )
    assert calls and calls[-1] == (5, 5)
    assert all(t == 5 for _, t in calls)
    assert [d for d, _ in calls] == sorted({d for d, _ in calls})
    # progress=True draws a bar and returns the same numbers.
    a = montecarlo.run("K1", CASE, runs=2, seed=1, steps=150, progress=True)
    b = montecarlo.run("K1", CASE, runs=2, seed=1, steps=150, progress=False)
    np.testing.assert_array_equal(
        a["estimators"]["EKF"]["errors"], b["estimators"]["EKF"]["errors"]
    )


def test_progress_exception_cancels() -> None:
    def stop(done: int, total: int) -> None:
        if done >= 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sim.run_monte_carlo("K1", CASE, runs=200, seed=1, progress=stop)
    with pytest.raises(TypeError):
        sim.run_monte_carlo("K1", CASE, runs=1, seed=1, progress=3)


def test_plots_agg(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPLBACKEND", "Agg")
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from nlosloc import plots

    assert os.environ["MPLBACKEND"] == "Agg"
    res = montecarlo.run("K1", CASE, runs=2, seed=1, steps=200, progress=False)
    ax = plots.error_cdf(res)
    assert ax.figure is not None
    assert len(ax.get_lines()) == len(res["estimators"])
    ax2 = plots.rmse_over_time(res)
    assert len(ax2.get_lines()) == len(res["estimators"])
    np.testing.assert_allclose(ax2.get_lines()[0].get_ydata(), montecarlo.rmse(res)["EKF"])
    fig, ax3 = plt.subplots()
    assert plots.error_cdf(res, ax=ax3, discard=False) is ax3
    plt.close("all")


def test_h1_h2_params_round_trip_and_checks() -> None:
    p = sim.H1Params()
    assert p.steps == 20000 and p.mean_los == 30.0 and p.mean_nlos == 5.0
    np.testing.assert_array_equal(p.start, [-1000.0, 400.0])
    np.testing.assert_array_equal(p.initial_std, [10.0, 10.0, 1.0, 1.0])
    np.testing.assert_array_equal(p.sector_deg, [90.0, 210.0, 330.0])
    p.start = np.array([-500.0, 300.0])
    np.testing.assert_array_equal(p.start, [-500.0, 300.0])
    with pytest.raises(
        ValueError, match=r"^H1Params\.start: expected shape \(2, 1\), got \(3, 1\)$"
    ):
        p.start = np.zeros(3)
    p.initial_std = np.array([10.0, 10.0, -1.0, 1.0])
    with pytest.raises(
        ValueError,
        match=r"^H1Params\.initial_std\[2\]: expected a finite value > 0, got -1\.000000$",
    ):
        sim.H1(p)
    q = sim.H2Params()
    assert q.side == 3000.0 and q.tau0_var == 10.0 and q.pf_particles == 1000000
    q.tau0_var = -1.0
    with pytest.raises(
        ValueError, match=r"^H2Params\.tau0_var: expected a finite value > 0, got -1\.000000$"
    ):
        sim.H2(q)
    q.tau0_var = 10.0
    q.side = 0.0
    with pytest.raises(
        ValueError, match=r"^H2Params\.side: expected a finite value > 0, got 0\.000000$"
    ):
        sim.H2(q)


def test_h1_accessors() -> None:
    h = sim.H1()
    assert isinstance(h, sim.Scenario)
    assert h.name == "H1" and h.cases == ["default"] and h.steps == 20000
    assert h.params.rbpf_particles == 8
    # sectors with broadsides 90, 210, 330 deg: bearing 0 is 30 deg from 330 and 90 from 90
    assert h.serving_sector(0.0) == 2
    assert h.serving_sector(np.pi / 2) == 0
    assert h.serving_sector(np.pi) == 1
    assert h.motion.dt == pytest.approx(0.01)
    assert h.sight_process.num_anchors == 1
    assert len(h.quality) == 2
    assert h.measurements.rows == 4


def test_h2_custom_params_reach_the_scenario_and_the_runner() -> None:
    p = sim.H2Params()
    p.side = 1500.0
    p.mean_nlos = 40.0
    p.steps = 150
    h = sim.H2(p)
    assert h.params.side == 1500.0
    np.testing.assert_allclose(np.linalg.norm(h.anchors, axis=1), 1500.0)
    # eq. (15): p_LN from E{L_LOS} = 10, p_NL from E{L_NLOS} = 40; w dt = 5 m/s * 0.01 s
    assert h.urr_switch_probability(0) == pytest.approx(0.05 / 10.05, rel=1e-14)
    assert h.urr_switch_probability(1) == pytest.approx(0.05 / 40.05, rel=1e-14)
    with pytest.raises(
        ValueError, match=r"^condition: expected 0 \(LOS -> NLOS\) or 1 \(NLOS -> LOS\), got 2$"
    ):
        h.urr_switch_probability(2)
    np.testing.assert_array_equal(h.prior_variances(), [1.0, 1.0, 10.0, 1.0, 1.0, 10.0])
    assert h.urr_nlos_span() == pytest.approx(327.5, abs=0.5)
    assert h.motion.dt == pytest.approx(0.01) and h.sight_process.num_anchors == 6
    d = h.draw("default", 3, 0)
    assert d["y"].shape == (150, 6)
    # the runner uses this scenario (150 steps, 1.5 km hexagon), not the registry's default H2
    res = sim.run_monte_carlo(h, "default", 1, 3, ["EKF-LOS", "URR"], 1)
    assert res["steps"] == 150
    assert res["estimators"]["URR"]["errors"].shape == (1, 150)
    ref = sim.run_monte_carlo("H2", "default", 1, 3, ["EKF-LOS"], 1, 150)
    assert not np.array_equal(
        res["estimators"]["EKF-LOS"]["errors"], ref["estimators"]["EKF-LOS"]["errors"]
    )
    with pytest.raises(ValueError, match="estimator: unknown estimator 'K1-EKF' for scenario H2"):
        sim.run_monte_carlo(h, "default", 1, 3, ["K1-EKF"], 1)


def test_descriptions_and_choices_report_the_parameters_used() -> None:
    # Default scenarios: lines copied from the output printed before the fields were formatted.
    h1_default = sim.H1().choices
    assert h1_default[0] == (
        "BS at the origin with sectors of 120 deg whose broadsides point at 90, 210 and 330 deg; "
        "the serving sector is the one whose span contains the mobile's bearing (the path changes "
        "sector twice, Fig. 10)"
    )
    assert sim.scenario("H2").choices[0] == (
        "anchors at the hexagon vertices (3000 cos(60 k deg), 3000 sin(60 k deg)), k = 0..5"
    )
    assert sim.scenario("K1").choices[3] == (
        "NLOS measurement = d + n + b with n ~ N(0, 50^2) and b = max(0, N(513, 436^2)) drawn "
        "every step: Sec. 6.1's Gaussian with Sec. 2's b_i(k) >= 0 (eq. 1); a negative draw (12%) "
        "is an NLOS link with no excess delay (mean of b 539 m). K1Params::nlos_nonnegative = "
        "false keeps the untruncated draw. The stack's NLOS row noise (for the model-based "
        "filters) stays N(513, 50^2 + 436^2)"
    )
    assert sim.scenario("K3").choices[3] == (
        "initial belief: truth + N(0, diag(2^2, 2^2, 0.1^2, 0.1^2)), covariance the same; first "
        "100 of 200 samples left out (Sec. 6's rule); P(error <= 5 m) pooled over runs and samples "
        "k >= 100"
    )
    assert sim.K2().description == (
        "Ke & Wu 2011 Sec. 6.2: K1's 3 TOA nodes and noise, every node alternating NLOS/LOS every "
        "200 samples, L = 2000, dt = 0.1 s"
    )

    h1 = sim.H1(sim.H1Params(start=(-500.0, 300.0), speed=3.0, mean_nlos=10.0))
    assert "mobile at 3 m/s" in h1.description and "10 m/s" not in h1.description
    assert "starts at (-500, 300) m heading +x at exactly 3 m/s" in h1.choices[2]
    assert "(-1000, 400)" not in h1.choices[2] and "10 m/s" not in h1.choices[2]
    assert "(p_N = 10/40 = 0.25)" in h1.choices[3]
    assert "never changes sector" in h1.choices[0]  # bearing 149 -> 72 deg: the 90-deg sector only

    h2 = sim.H2(sim.H2Params(side=1500.0, rtoa_nlos_var=800.0, mean_nlos=40.0))
    assert "1500" in h2.choices[0] and "3000" not in h2.choices[0]
    assert "1.5 km hexagon" in h2.description and "E{L_NLOS} = 40 m" in h2.description
    assert "variance 800 (" in h2.choices[2] and "5000" not in h2.choices[2]
    sigma = np.sqrt(800.0 / (2.0 - np.pi / 2.0))  # Rayleigh scale of the NLOS noise
    w = sigma * np.sqrt(-2.0 * np.log(0.01))  # its 99% quantile, URR's W
    assert h2.urr_nlos_span() == pytest.approx(w, rel=1e-12)
    assert f"W = {w:.4g} m" in h2.choices[-1] and "327" not in h2.choices[-1]
    assert "P(NLOS) = 0.8 at t = 0" in h2.choices[-1] and "(p_N = 0.8)" in h2.choices[3]
    header = sim.format_choices(h2)
    assert "1500 cos(60 k deg)" in header and "3000" not in header

    k1 = sim.K1(sim.K1Params(steps=300, dt=0.2, sigma_los=30.0))
    assert "L = 300, dt = 0.2 s" in k1.description
    assert "L = 2000" not in k1.description and "dt = 0.1 s" not in k1.description
    assert "R = 30^2 I" in k1.choices[6] and "50^2" not in k1.choices[6]

    k2 = sim.K2(sim.K2Params(base=sim.K1Params(steps=300, dt=0.2), period=50, start_nlos=False))
    assert "alternating LOS/NLOS every 50 samples, L = 300, dt = 0.2 s" in k2.description
    assert "samples [0, 50) LOS, [50, 100) NLOS" in k2.choices[0] and "200" not in k2.choices[0]

    k3 = sim.K3(sim.K3Params(threshold=3.0, sigma_rel=0.05))
    assert "P(error <= 3 m)" in k3.description and "5 m" not in k3.description
    assert "P(error <= 3 m)" in k3.choices[3] and "<= 5 m" not in k3.choices[3]
    assert "n_i ~ N(0, (0.05 d_i)^2)" in k3.choices[2] and "0.02" not in k3.choices[2]


def test_runs_refuse_repeats_explicit_zero_steps_and_runs_without_statistics() -> None:
    with pytest.raises(ValueError, match="^estimators: 'EKF' appears more than once$"):
        sim.run_monte_carlo("K1", CASE, 1, 1, ["EKF", "EKF"], steps=200)
    with pytest.raises(
        ValueError, match=r"^steps: expected >= 1 \(None: the scenario's default\), got 0$"
    ):
        sim.run_monte_carlo("K1", CASE, 1, 1, ["EKF"], steps=0)
    with pytest.raises(ValueError, match="^steps: expected >= 1"):
        sim.draw("K1", CASE, 1, 0, steps=0)
    msg = "^steps: expected more than the scenario's 100 discarded first steps, got 50$"
    with pytest.raises(ValueError, match=msg):
        sim.run_monte_carlo("K1", CASE, 1, 1, ["EKF"], steps=50)
    assert sim.draw("K1", CASE, 1, 0)["y"].shape[0] == 2000  # None: the default
