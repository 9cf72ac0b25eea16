"""Python API of the filters: shapes, missing rows, bad input (ValueError naming the argument)
and the state left unchanged after a rejected call."""

import numpy as np
import pytest

from nlosloc import core, filters, models, noise

ANCHORS = np.array([[0.0, 0.0], [8600.0, 0.0], [4300.0, 7500.0]])


def stack(conditions=2):
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), ANCHORS, conditions)
    for b in range(3):
        dists = [noise.Normal(0.0, 50.0)]
        if conditions == 2:
            dists.append(noise.ShiftedNormal(513.0, 436.0))
        st.add_toa(b, dists)
    return st


MOTION = models.ConstantVelocity2(0.1, 1.0, models.VelocityNoise.WhiteAcceleration)
X0 = np.array([1000.0, 1000.0, 10.0, 15.0])
P0 = np.diag([2500.0, 2500.0, 100.0, 100.0])


@pytest.mark.parametrize("cls", [filters.Ekf, filters.Ukf, filters.UkfAugmented])
def test_run_shapes_and_missing(cls):
    f = cls(MOTION, stack(), X0, P0)
    Y = np.tile([1420.0, 7650.0, 6700.0], (5, 1))
    Y[2, 1] = np.nan
    out = f.run(Y, sight=np.array([0, 1, 0]))
    assert out["mean"].shape == (5, 4)
    assert out["cov"].shape == (5, 4, 4)
    assert list(out["rows_used"]) == [3, 3, 2, 3, 3]
    assert np.isfinite(out["log_likelihood"]).all()
    np.testing.assert_allclose(out["mean"][-1], f.mean)
    assert f.time == pytest.approx(0.5)


@pytest.mark.parametrize("cls", [filters.Ekf, filters.Ukf, filters.UkfAugmented])
@pytest.mark.parametrize("scheme", [core.SigmaScheme.scaled(0.5), core.SigmaScheme.cubature()])
def test_a_nan_row_is_the_row_left_out(cls, scheme):
    # UkfAugmented kept the missing row's noise input in its sigma set (n + q fixed): 0.012 m off in
    # five steps with the cubature rule. Now every filter equals the one built without the row.
    part = models.MeasurementStack(models.ConstantVelocity2.layout(), ANCHORS, 2)
    for b in (0, 2):
        part.add_toa(b, [noise.Normal(0.0, 50.0), noise.ShiftedNormal(513.0, 436.0)])
    kw = {} if cls is filters.Ekf else {"scheme": scheme}
    f, g = cls(MOTION, stack(), X0, P0, **kw), cls(MOTION, part, X0, P0, **kw)
    for k in range(5):
        y = np.array([1420.0 + 10 * k, np.nan, 6700.0 - 5 * k])
        rf, rg = f.step(y, sight=[0, 1, 1]), g.step(y[[0, 2]], sight=[0, 1, 1])
        assert rf.log_likelihood == pytest.approx(rg.log_likelihood, rel=1e-12)
    np.testing.assert_allclose(f.mean, g.mean, rtol=1e-12)
    np.testing.assert_allclose(f.cov, g.cov, rtol=1e-10, atol=1e-9)


def check_unchanged(f, x, P, t):
    np.testing.assert_array_equal(f.mean, x)
    np.testing.assert_array_equal(f.cov, P)
    assert f.time == t


@pytest.mark.parametrize("cls", [filters.Ekf, filters.Ukf, filters.UkfAugmented])
def test_bad_input_names_argument_and_keeps_state(cls):
    f = cls(MOTION, stack(), X0, P0)
    f.step(np.array([1420.0, 7650.0, 6700.0]))
    x, P, t = f.mean, f.cov, f.time
    with pytest.raises(ValueError, match=r"y: expected shape \(3, 1\), got \(2, 1\)"):
        f.step(np.array([1.0, 2.0]))
    check_unchanged(f, x, P, t)
    with pytest.raises(ValueError, match="got inf at row 2"):
        f.step(np.array([1.0, 2.0, np.inf]))
    check_unchanged(f, x, P, t)
    with pytest.raises(ValueError, match=r"sight: expected conditions in \[0, 2\)"):
        f.step(np.array([1.0, 2.0, 3.0]), sight=np.array([0, 5, 0]))
    check_unchanged(f, x, P, t)
    with pytest.raises(
        ValueError,
        match=r"^step 1: Y: expected finite values, or NaN for a missing row; got inf at row 1$",
    ):
        f.run(np.array([[1.0, 2.0, 3.0], [1.0, np.inf, 3.0]]))
    check_unchanged(f, x, P, t)
    with pytest.raises(ValueError, match="sight: expected shape"):
        f.run(np.ones((2, 3)), sight=np.zeros((3, 3), dtype=int))
    check_unchanged(f, x, P, t)
    bad = P.copy()
    bad[0, 0] = -1.0
    with pytest.raises(ValueError, match="belief.cov: expected a symmetric positive definite"):
        f.set_belief(x, bad)
    check_unchanged(f, x, P, t)
    with pytest.raises(ValueError, match="mean: expected shape"):
        f.set_belief(np.zeros(3), P)
    check_unchanged(f, x, P, t)


def test_constructor_errors():
    with pytest.raises(ValueError, match="initial.cov: expected a symmetric positive definite"):
        filters.Ukf(MOTION, stack(), X0, -P0)
    with pytest.raises(ValueError, match="initial.mean: expected finite"):
        filters.Ukf(MOTION, stack(), np.array([np.nan, 0, 0, 0]), P0)
    with pytest.raises(ValueError, match="cov: expected shape"):
        filters.Ekf(MOTION, stack(), X0, np.eye(3))
    with pytest.raises(ValueError, match="alpha"):
        filters.Ukf(MOTION, stack(), X0, P0, core.SigmaScheme.scaled(0.0))
    with pytest.raises(ValueError, match="motion: expected"):
        filters.Ukf("cv", stack(), X0, P0)
    with pytest.raises(ValueError, match="anchors"):
        models.MeasurementStack(models.ConstantVelocity2.layout(), np.array([[0.0, np.nan]]), 2)
    with pytest.raises(ValueError, match="anchors: expected shape"):
        models.MeasurementStack(models.ConstantVelocity2.layout(), np.zeros((3, 3)), 2)
    with pytest.raises(ValueError, match="dt"):
        models.ConstantVelocity2(-0.1, 1.0)
    with pytest.raises(ValueError, match="sigma2"):
        models.ConstantVelocity2(0.1, -1.0)
    with pytest.raises(ValueError, match="add_toa: noise"):
        stack().add_toa(0, [noise.Normal(0.0, 1.0)])
    with pytest.raises(ValueError, match="R: expected a symmetric positive definite"):
        filters.Kf(MOTION, np.eye(2, 4), -np.eye(2), X0, P0)


def test_jacobian_matches_finite_differences():
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), ANCHORS, 1)
    st.add_toa(0, [noise.Normal(0.0, 1.0)]).add_aoa(1, [noise.Normal(0.0, 0.1)])
    st.add_tdoa(1, 2, [noise.Normal(0.0, 1.0)], [noise.Normal(0.0, 1.0)])
    st.add_aoa_phase(2, 0.5, [noise.Normal(0.0, 0.1)])
    x = np.array([1200.0, 3400.0, 1.0, -2.0])
    J = st.jacobian(x)
    Jn = np.zeros_like(J)
    for k in range(4):
        h = 1e-5 * max(1.0, abs(x[k]))
        e = np.zeros(4)
        e[k] = h
        Jn[:, k] = st.residual(st.predict(x + e), st.predict(x - e)) / (2 * h)
    np.testing.assert_allclose(J, Jn, rtol=1e-6, atol=1e-9)


def test_ukf_tracks_with_sight():
    """With the true sight the UKF handles an NLOS node that ruins the LOS-only filter (seeded)."""
    rng = np.random.default_rng(5)
    T = 600
    x = X0.copy()
    truth, Y = [], []
    for _ in range(T):
        x = MOTION.F @ x
        d = np.linalg.norm(x[:2] - ANCHORS, axis=1)
        y = d + 50 * rng.standard_normal(3)
        y[2] += 513 + 436 * rng.standard_normal()
        truth.append(x[:2].copy())
        Y.append(y)
    truth, Y = np.array(truth), np.array(Y)
    aware = filters.Ukf(MOTION, stack(), X0, P0).run(Y, sight=np.array([0, 0, 1]))
    blind = filters.Ukf(MOTION, stack(), X0, P0).run(Y)
    e_aware = np.linalg.norm(aware["mean"][100:, :2] - truth[100:], axis=1)
    e_blind = np.linalg.norm(blind["mean"][100:, :2] - truth[100:], axis=1)
    assert np.percentile(e_aware, 67) < 60.0
    assert np.percentile(e_blind, 67) > 150.0
