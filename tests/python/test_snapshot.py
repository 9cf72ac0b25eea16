"""nlosloc.snapshot: the per-epoch baselines of Huerta et al. 2009 Sec. VI (MleLos, Chen, Cong,
Urruela) on hand-built geometries, their argument checks, and the H1/H2 scenarios through the
registry."""

import numpy as np
import pytest

from nlosloc import models, noise, sim, snapshot

HEX = np.array([[3000.0 * np.cos(k * np.pi / 3), 3000.0 * np.sin(k * np.pi / 3)] for k in range(6)])


def rtoa_stack():
    st = models.MeasurementStack(models.ConstantVelocityClock2.layout(), HEX, 2)
    for b in range(6):
        st.add_rtoa(b, [noise.Normal(0.0, np.sqrt(10.0)), noise.Rayleigh.from_variance(5000.0)])
    return st


def rtoa(p, tau, bias, sigma, rng):
    return np.linalg.norm(HEX - p, axis=1) + tau + bias + sigma * rng.standard_normal(6)


def test_los_solver_exact_rtoa():
    s = snapshot.LosSolver(rtoa_stack())
    assert s.unknowns == 3 and s.has_clock
    p = np.array([123.0, -456.0])
    y = np.linalg.norm(HEX - p, axis=1) + 7.5
    lin = s.linear_start(y)
    np.testing.assert_allclose(lin, [123.0, -456.0, 7.5], atol=1e-6)
    f = s.solve(y, np.array([500.0, 500.0, 0.0]))
    assert f.converged
    np.testing.assert_allclose(f.theta, [123.0, -456.0, 7.5], atol=1e-5)
    # A subset of rows: the first three anchors only leave no redundancy (cost 0).
    f3 = s.solve(y, np.array([0.0, 0.0, 0.0]), use=[True, True, True, False, False, False])
    assert f3.rows == 3 and f3.cost < 1e-9


def test_los_solver_solve_los_is_solve_with_the_defaults():
    s = snapshot.LosSolver(rtoa_stack())
    rng = np.random.default_rng(4)
    y = rtoa(np.array([40.0, -25.0]), 3.0, 0.0, 2.0, rng)
    y[2] = np.nan  # a missing row is skipped by both
    t0 = np.array([0.0, 0.0, 0.0])
    a, b = s.solve_los(y, t0), s.solve(y, t0)
    np.testing.assert_array_equal(a.theta, b.theta)
    fields = ("cost", "rows", "iterations", "converged")
    assert [getattr(a, f) for f in fields] == [getattr(b, f) for f in fields]
    assert a.rows == 5 and a.converged
    with pytest.raises(ValueError, match="theta0"):
        s.solve_los(y, np.zeros(2))


def test_mle_los_polar_inversion():
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), np.zeros((1, 2)), 2)
    st.add_toa(0, [noise.Normal(0.0, 3.0), noise.Rayleigh.from_variance(2000.0)])
    st.add_aoa_phase(0, np.pi / 2, [noise.Normal(0.0, 3e-3), noise.Normal(0.0, 3e-2)])
    mle = snapshot.MleLos(st)
    p = np.array([-300.0, 400.0])
    y = np.array([np.linalg.norm(p), np.pi * np.sin(np.arctan2(p[1], p[0]) - np.pi / 2)])
    r = mle.solve(y)
    assert r["valid"]
    np.testing.assert_allclose(r["theta"], p, atol=1e-6)
    assert not mle.classifies_sight


def test_chen_cong_urr_with_two_nlos_anchors():
    st = rtoa_stack()
    rng = np.random.default_rng(7)
    p = np.array([250.0, -100.0])
    bias = np.array([0.0, 180.0, 0.0, 0.0, 260.0, 0.0])
    chen = snapshot.Chen(st)
    cong = snapshot.Cong(st)
    opt = snapshot.UrruelaOptions()
    opt.nlos_span = 330.0
    urr = snapshot.Urruela(st, opt)
    assert len(chen.combinations) == 22
    assert len(urr.hypotheses) == 42
    truth = (bias > 0).astype(int)
    err = {"chen": [], "cong": [], "urr": []}
    for e in range(25):
        y = rtoa(p, 3.0, bias, np.sqrt(10.0), rng)
        err["chen"].append(np.linalg.norm(chen.solve(y)["theta"][:2] - p))
        rc = cong.solve(y)
        err["cong"].append(np.linalg.norm(rc["theta"][:2] - p))
        ru = urr.solve(y)
        err["urr"].append(np.linalg.norm(ru["theta"][:2] - p))
        if e >= 5:
            np.testing.assert_array_equal(ru["sight"], truth)
    for name, v in err.items():
        assert np.mean(v) < 15.0, name
    assert cong.enough_los
    np.testing.assert_array_equal(cong.sight, truth)
    a = cong.nlos_noise[0]
    assert a.sigma_right > a.sigma_left and 60.0 < a.center < 160.0


def test_bad_arguments_raise_value_error():
    st = rtoa_stack()
    s = snapshot.LosSolver(st)
    with pytest.raises(ValueError, match="theta0"):
        s.solve(np.zeros(6), np.zeros(2))
    with pytest.raises(ValueError, match="y"):
        s.solve(np.zeros(5), np.zeros(3))
    o = snapshot.ChenOptions()
    o.reject_fraction = 1.0
    with pytest.raises(ValueError, match="reject_fraction"):
        snapshot.Chen(st, o)
    with pytest.raises(ValueError, match="start"):
        snapshot.Cong(st).reset(np.zeros(2))
    with pytest.raises(ValueError, match="sigma_left"):
        snapshot.RowNoise(0.0, -1.0, 1.0)
    # inf was taken: Chen's weights 1 / inf = 0 gave a NaN fix marked valid, and an infinite step
    # tolerance ended every solve after one step, reported converged
    with pytest.raises(ValueError, match=r"^opt\.residual_floor: expected a finite value > 0$"):
        snapshot.Chen(st, snapshot.ChenOptions(residual_floor=np.inf))
    gn = snapshot.GaussNewtonOptions(step_tolerance=np.inf)
    for make in (
        lambda: snapshot.LosSolver(st, gn),
        lambda: snapshot.MleLos(st, gn),
        lambda: snapshot.Chen(st, gauss_newton=gn),
        lambda: snapshot.Cong(st, gauss_newton=gn),
    ):
        with pytest.raises(ValueError, match=r"^opt\.step_tolerance: expected a finite value > 0$"):
            make()


def test_h_scenarios_registered_and_run():
    assert {"H1", "H2"} <= set(sim.scenarios())
    info = sim.scenario_info("H2")
    for name in ("EKF-LOS", "CHEN", "CONG", "URR"):
        assert name in info["estimators"]
    res = sim.run_monte_carlo("H2", "default", 1, 3, ["CHEN", "URR"], 1, 200, None)
    for name in ("CHEN", "URR"):
        assert res["estimators"][name]["errors"].shape == (1, 200)
        assert np.isfinite(res["estimators"][name]["errors"]).all()


def test_row_noise_rejects_bad_values():
    with pytest.raises(ValueError, match=r"^RowNoise\.center: expected a finite value, got nan$"):
        snapshot.RowNoise.gaussian(np.nan, 1.0)
    with pytest.raises(
        ValueError, match=r"^RowNoise\.sigma_left: expected a finite value > 0, got 0\.000000$"
    ):
        snapshot.RowNoise.gaussian(0.0, 0.0)
    r = snapshot.RowNoise(1.0, 2.0, 3.0)
    with pytest.raises(
        ValueError, match=r"^RowNoise\.sigma_right: expected a finite value > 0, got -1\.000000$"
    ):
        r.sigma_right = -1.0
    with pytest.raises(ValueError, match=r"^RowNoise\.center: expected a finite value, got inf$"):
        r.center = np.inf
    assert (r.center, r.sigma_left, r.sigma_right) == (
        1.0,
        2.0,
        3.0,
    )  # unchanged by the rejected sets
    r.sigma_left = 5.0
    assert r.sigma_left == 5.0 and r.valid()


def test_los_solver_checks_row_arguments():
    s = snapshot.LosSolver(rtoa_stack())
    with pytest.raises(ValueError, match=r"^y: expected shape \(6, 1\), got \(5, 1\)$"):
        s.linear_start(np.zeros(5))
    with pytest.raises(ValueError, match=r"^use: expected one flag per row \(6\), got 5$"):
        s.linear_start(np.full(6, 3000.0), [True] * 5)
    with pytest.raises(ValueError, match=r"^noise: expected one RowNoise per row \(6\), got 1$"):
        s.solve(np.full(6, 3000.0), np.zeros(3), None, [snapshot.RowNoise.gaussian(0.0, 1.0)])
    with pytest.raises(ValueError, match=r"^y: expected shape \(6, 1\), got \(5, 1\)$"):
        snapshot.MleLos(rtoa_stack()).solve(np.zeros(5))


def test_los_solver_residuals_cost_rows_of():
    s = snapshot.LosSolver(rtoa_stack())
    assert s.space_dim == 2 and s.unknowns == 3
    assert s.options.max_iterations == 30
    # at the centre with clock 0 every anchor is 3000 m away: residual y - 3000
    y = np.array([3001.0, 2999.0, 3002.0, 3000.0, 3000.0, 2997.0])
    np.testing.assert_allclose(s.residuals(y, np.zeros(3)), y - 3000.0, atol=1e-9)
    # LOS sigma^2 = 10: (1 + 1 + 4 + 0 + 0 + 9) / 10
    assert s.cost(y, np.zeros(3)) == pytest.approx(1.5, rel=1e-12)
    assert s.cost(y, np.zeros(3), [True, True, False, False, False, False]) == pytest.approx(
        0.2, rel=1e-12
    )
    assert s.rows_of(0b000101) == [True, False, True, False, False, False]
    with pytest.raises(ValueError, match=r"^theta: expected shape \(3, 1\), got \(2, 1\)$"):
        s.residuals(y, np.zeros(2))


def test_subsets_and_mask_count():
    assert snapshot.mask_count(0b101101) == 4
    v = snapshot.subsets_at_least(4, 3)
    assert v == [0b1111, 0b0111, 0b1011, 0b1101, 0b1110]
    with pytest.raises(ValueError, match="num_anchors"):
        snapshot.subsets_at_least(21, 1)
