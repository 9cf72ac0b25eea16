"""The UKF against FilterPy's UnscentedKalmanFilter on the same model (issue #2).

Model: constant velocity (Ke and Wu eq. 16 white acceleration), 3 TOA anchors, 200 steps.
nlosloc's UKF predicts with the exact linear equations and draws the update's sigma points from
the predicted (x, P); FilterPy propagates its sigma points through f and reuses them in the update.
For a linear f the two agree in (x, P) but not in the point sets, so after each FilterPy predict we
redraw ``sigmas_f`` from (x, P) to compare the same algorithm (see filters/ukf.hpp).
"""

import numpy as np
import pytest

from nlosloc import core, filters, models, noise

filterpy_kalman = pytest.importorskip("filterpy.kalman")

ANCHORS = np.array([[0.0, 0.0], [8600.0, 0.0], [4300.0, 7500.0]])
DT = 0.1
SIGMA = 50.0


def make_track(seed, steps=200):
    motion = models.ConstantVelocity2(DT, 1.0, models.VelocityNoise.WhiteAcceleration)
    rng = np.random.default_rng(seed)
    x = np.array([1000.0, 1000.0, 10.0, 15.0])
    L = np.linalg.cholesky(motion.Q + 1e-18 * np.eye(4))
    ys = []
    for _ in range(steps):
        x = motion.F @ x + L @ rng.standard_normal(4)
        d = np.linalg.norm(x[:2] - ANCHORS, axis=1)
        ys.append(d + SIGMA * rng.standard_normal(3))
    return motion, np.array(ys)


def toa_stack():
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), ANCHORS, 1)
    for b in range(3):
        st.add_toa(b, [noise.Normal(0.0, SIGMA)])
    return st


@pytest.mark.parametrize("alpha,beta,kappa", [(0.5, 2.0, 0.0), (1.0, 2.0, 1.0), (0.3, 2.0, -1.0)])
def test_ukf_matches_filterpy(alpha, beta, kappa):
    motion, Y = make_track(7)
    x0 = np.array([1050.0, 960.0, 8.0, 14.0])
    P0 = np.diag([2500.0, 2500.0, 100.0, 100.0])

    points = filterpy_kalman.MerweScaledSigmaPoints(4, alpha=alpha, beta=beta, kappa=kappa)
    F = motion.F

    def fx(x, dt):
        return F @ x

    def hx(x):
        return np.linalg.norm(x[:2] - ANCHORS, axis=1)

    ref = filterpy_kalman.UnscentedKalmanFilter(
        dim_x=4, dim_z=3, dt=DT, hx=hx, fx=fx, points=points
    )
    ref.x = x0.copy()
    ref.P = P0.copy()
    ref.Q = motion.Q.copy()
    ref.R = SIGMA**2 * np.eye(3)

    ukf = filters.Ukf(motion, toa_stack(), x0, P0, core.SigmaScheme.scaled(alpha, beta, kappa))
    out = ukf.run(Y)

    for k in range(len(Y)):
        ref.predict()
        ref.sigmas_f = points.sigma_points(
            ref.x, ref.P
        )  # same point set as nlosloc (module docstring)
        ref.update(Y[k])
        np.testing.assert_allclose(out["mean"][k], ref.x, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(out["cov"][k], ref.P, rtol=1e-9, atol=1e-9 * np.abs(ref.P).max())
        assert out["log_likelihood"][k] == pytest.approx(ref.log_likelihood, rel=1e-9, abs=1e-9)
    assert np.all(out["rows_used"] == 3)


def test_sigma_points_match_filterpy_order():
    points = filterpy_kalman.MerweScaledSigmaPoints(4, alpha=0.5, beta=2.0, kappa=0.0)
    x = np.array([1.0, 2.0, 3.0, 4.0])
    P = np.array([[4.0, 1, 0, 0], [1, 3, 0.5, 0], [0, 0.5, 2, 0.1], [0, 0, 0.1, 1]])
    ours = core.sigma_points(x, P, core.SigmaScheme.scaled(0.5, 2.0, 0.0))
    np.testing.assert_allclose(ours, points.sigma_points(x, P), rtol=1e-13, atol=1e-13)
    w = core.SigmaScheme.scaled(0.5, 2.0, 0.0).weights(4)
    np.testing.assert_allclose([w.wm0, w.wc0], [points.Wm[0], points.Wc[0]], rtol=1e-14)
    np.testing.assert_allclose(w.wi, points.Wm[1], rtol=1e-14)


def test_kf_and_ukf_agree_on_linear_model():
    motion = models.ConstantVelocity2(DT, 1.0, models.VelocityNoise.WhiteAcceleration)
    H = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [1.0, 1.0, 0.5, 0]])
    sd = np.array([2.0, 3.0, 1.5])
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), np.zeros((1, 2)), 1)
    for i in range(3):
        st.add_linear(H[i], -1, [noise.Normal(0.0, sd[i])])
    x0, P0 = np.array([10.0, -5, 1, 0.5]), np.diag([100.0, 80, 4, 3])
    kf = filters.Kf(motion, H, np.diag(sd**2), x0, P0)
    ukf = filters.Ukf(motion, st, x0, P0, core.SigmaScheme.scaled(0.5, 2.0, 0.0))
    rng = np.random.default_rng(3)
    for _ in range(100):
        y = H @ np.array([10.0, -5, 1, 0.5]) + sd * rng.standard_normal(3)
        a, b = kf.step(y), ukf.step(y)
        np.testing.assert_allclose(kf.mean, ukf.mean, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(kf.cov, ukf.cov, rtol=1e-9, atol=1e-12)
        assert a.log_likelihood == pytest.approx(b.log_likelihood, abs=1e-9)
