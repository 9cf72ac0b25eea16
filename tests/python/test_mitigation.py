"""nlosloc.mitigation: Ke & Wu 2011's QP adapter, Sec. 3 bias estimation, the proposed tracker
and the bias-augmented (iterated NLOS) EKF through the Python bindings, plus an osqp check of the
QPs that the bias estimation actually builds."""

from __future__ import annotations

import re

import numpy as np
import pytest

from box_qp_helpers import osqp_box
from nlosloc import mitigation, models

ANCHORS = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])
EXACT = np.array([5.0, np.sqrt(65.0), np.sqrt(45.0)])  # ranges from (3, 4)
K1_ANCHORS = np.array([[0.0, 0.0], [8600.0, 0.0], [4300.0, 7500.0]])


def motion(dt: float = 0.1, accel: float = 1.0) -> models.ConstantVelocity2:
    return models.ConstantVelocity2(dt, accel, models.VelocityNoise.WhiteAcceleration)


def exact(msg: str) -> str:
    """A pytest.raises match for exactly this message."""
    return "^" + re.escape(msg) + "$"


@pytest.mark.parametrize("solver", ["default", "enumeration", "proxsuite"])
def test_box_qp_small_problem_and_errors(solver: str) -> None:
    if solver == "proxsuite" and not mitigation.have_proxsuite_box_qp:
        pytest.skip("nlosloc built without proxsuite")
    qp = mitigation.make_box_qp(3, solver=solver)
    general = "proxsuite-dense" if mitigation.have_proxsuite_box_qp else "enumeration"
    expected = {"default": general, "enumeration": "enumeration", "proxsuite": "proxsuite-dense"}
    assert qp.name == expected[solver]
    h = np.diag([2.0, 0.0, 1.0])
    res = qp.solve(h, np.array([-4.0, 1.0, 3.0]), np.zeros(3), np.array([1.0, 5.0, 5.0]))
    assert res.ok() and res.status == mitigation.QpStatus.Solved
    np.testing.assert_allclose(qp.x, [1.0, 0.0, 0.0], atol=1e-7)
    assert res.objective == pytest.approx(-3.0, abs=1e-7)
    with pytest.raises(ValueError, match=r"^n: expected 1 <= n <= 8 variables for the enumeration"):
        mitigation.make_box_qp(9, solver="enumeration")
    # QpBiasEkf's default: the enumeration for the (positive definite) prediction-referenced QP, the
    # general default for the rank-deficient snapshot form (Sec. 3), as BiasEstimator
    m4 = motion()
    f = mitigation.QpBiasEkf(m4, ANCHORS, np.array([3.0, 4.0, 0, 0]), np.eye(4))
    assert f.solver_name == "enumeration"
    opt = mitigation.QpBiasEkfOptions()
    opt.reference = mitigation.BiasReference.Snapshot
    f = mitigation.QpBiasEkf(m4, ANCHORS, np.array([3.0, 4.0, 0, 0]), np.eye(4), opt)
    assert f.solver_name == general
    assert mitigation.BiasEstimator(ANCHORS).solver_name == general
    assert mitigation.BiasEstimator(ANCHORS, solver="enumeration").solver_name == "enumeration"
    with pytest.raises(ValueError, match="lower"):
        qp.solve(h, np.zeros(3), np.ones(3), np.zeros(3))
    with pytest.raises(ValueError, match="solver"):
        mitigation.make_box_qp(3, solver="nope")
    failing = mitigation.make_box_qp(3, solver="failing")
    assert (
        failing.solve(h, np.zeros(3), np.zeros(3), np.ones(3)).status == mitigation.QpStatus.Failed
    )


def test_bias_estimation_eqs_10_to_15() -> None:
    est = mitigation.BiasEstimator(ANCHORS)
    e = est.estimate(EXACT, np.ones(3))
    assert e.flags == 0
    assert e.reference.kind == mitigation.ReferenceKind.FeasibleVertices
    np.testing.assert_allclose(e.reference.point, [3.0, 4.0], atol=1e-9)
    h0 = np.array([[0.6, 0.8], [-7, 4] / np.sqrt(65), [3, -6] / np.sqrt(45)])
    np.testing.assert_allclose(est.H0, h0, atol=1e-12)
    np.testing.assert_allclose(est.U @ est.H0, -np.eye(2), atol=1e-12)  # eq. (11)
    np.testing.assert_allclose(est.L @ est.H0, 0.0, atol=1e-12)  # eq. (12)
    np.testing.assert_allclose(est.sigma_v, est.L @ est.L.T, atol=1e-12)  # eq. (13), R = I
    l23 = np.sqrt(200.0)
    np.testing.assert_allclose(
        e.upper,
        [5 + np.sqrt(45) - 10, np.sqrt(65) + np.sqrt(45) - l23, np.sqrt(65) + np.sqrt(45) - l23],
    )
    np.testing.assert_allclose(e.bias, 0.0, atol=1e-6)


def test_bias_estimation_fallbacks() -> None:
    est = mitigation.BiasEstimator(ANCHORS)
    e = est.estimate(np.array([3.0, 3.0, 6.0]), np.ones(3), hint=np.array([2.0, 2.0]))
    assert e.flags & mitigation.FLAG_BOUNDS_CLAMPED
    assert e.flags & mitigation.FLAG_REFERENCE_FALLBACK
    assert e.reference.kind == mitigation.ReferenceKind.Hint
    assert np.all(np.isfinite(e.bias)) and np.all(e.bias <= e.upper)
    failing = mitigation.BiasEstimator(ANCHORS, solver="failing")
    e = failing.estimate(EXACT + np.array([0, 0, 2.0]), np.ones(3))
    assert e.flags & mitigation.FLAG_QP_FAILED
    np.testing.assert_array_equal(e.bias, 0.0)
    with pytest.raises(ValueError, match="variances"):
        est.estimate(EXACT, -np.ones(3))
    with pytest.raises(ValueError, match="anchors"):
        mitigation.BiasEstimator(ANCHORS[:2])


def test_bias_qps_match_osqp() -> None:
    """The QPs of eq. (14) built from random K1-like ranges: proxsuite's objective equals osqp's."""
    pytest.importorskip("osqp")
    rng = np.random.default_rng(4)
    est = mitigation.BiasEstimator(K1_ANCHORS)
    qp = mitigation.make_box_qp(3)
    for _ in range(50):
        p = rng.uniform([500, 500], [5000, 5000])
        d = np.linalg.norm(p - K1_ANCHORS, axis=1)
        z = d + rng.normal(0, 50, 3) + rng.normal(513, 436, 3) * (rng.random(3) < 0.7)
        e = est.estimate(z, np.full(3, 2500.0), hint=p)
        h, g = est.qp_hessian, est.qp_gradient
        s = np.sqrt(2500.0)
        lo, up = e.lower / s, e.upper / s
        assert qp.solve(h, g, lo, up).ok()
        xo = np.clip(osqp_box(h, g, lo, up, 1e-11, 200000).x, lo, up)
        fo = 0.5 * xo @ h @ xo + g @ xo
        f = 0.5 * qp.x @ h @ qp.x + g @ qp.x
        assert abs(f - fo) <= 1e-6 * max(1.0, abs(fo))


def test_bias_from_innovation_hand_computed() -> None:
    # Eq. (14) with r = innovation, L = I, Sigma_v = D (eq. 27): the C++ test's hand-computed case.
    est = mitigation.BiasEstimator(ANCHORS)
    z = np.full(3, 20.0)
    d = np.array([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]])
    e = est.estimate_from_innovation(z, np.array([1.0, -1.0, 0.0]), d)
    assert e.qp.ok() and e.flags == 0
    np.testing.assert_allclose(e.bias, [1.5, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(e.upper, [30.0, 40.0 - np.sqrt(200.0), 40.0 - np.sqrt(200.0)])
    with pytest.raises(ValueError, match="D"):
        est.estimate_from_innovation(z, np.zeros(3), np.eye(2))
    opt = mitigation.QpBiasEkfOptions()
    assert opt.reference == mitigation.BiasReference.Prediction and opt.drop_free_rows


def test_options_validate_names_the_field_the_tracker_refuses() -> None:
    n = mitigation.RangeNoise(2.0, 0.01)
    n.validate()
    n.min_std = 0.0  # fields are not checked when set
    with pytest.raises(ValueError, match=r"^noise\.min_std: expected a finite value > 0, got 0"):
        n.validate()
    with pytest.raises(ValueError, match=r"^R\.min_std: expected a finite value > 0"):
        n.validate("R")
    q = mitigation.QpBiasEkfOptions()
    q.validate()
    q.gamma = 0.5
    with pytest.raises(ValueError, match=r"^options\.gamma: expected a finite value >= 1"):
        q.validate()
    with pytest.raises(ValueError, match=r"^options\.gamma: expected a finite value >= 1"):
        mitigation.QpBiasEkf(motion(), ANCHORS, np.zeros(4), np.eye(4), q)
    q.gamma = 2.0
    q.noise.relative = -1.0
    with pytest.raises(ValueError, match=r"^options\.noise\.relative: expected a finite value"):
        q.validate()
    b = mitigation.BiasAugmentedEkfOptions()
    b.validate()
    b.iterations = 0
    with pytest.raises(ValueError, match=r"^options\.iterations: expected 1\.\.100, got 0"):
        b.validate()
    b.iterations, b.bias_prior_std = 3, float("nan")
    with pytest.raises(ValueError, match=r"^options\.bias_prior_std: expected a finite value > 0"):
        b.validate()


@pytest.mark.parametrize(
    ("value", "shown"), [(-1.0, "-1.000000"), (float("inf"), "inf"), (float("nan"), "nan")]
)
def test_options_sparsity_is_validated_as_the_tracker_refuses_it(value: float, shown: str) -> None:
    # validate() passed sparsity = -1, which the constructor refused as "sparsity: ..."
    q = mitigation.QpBiasEkfOptions()
    q.sparsity = value
    msg = exact(f"options.sparsity: expected a finite value >= 0, got {shown}")
    with pytest.raises(ValueError, match=msg):
        q.validate()
    for reference in [mitigation.BiasReference.Prediction, mitigation.BiasReference.Snapshot]:
        q.reference = reference
        with pytest.raises(ValueError, match=msg):
            mitigation.QpBiasEkf(motion(), ANCHORS, np.zeros(4), np.eye(4), q)
    q.sparsity = 0.25
    q.validate()
    f = mitigation.QpBiasEkf(motion(), ANCHORS, np.zeros(4), np.eye(4), q)
    assert f.bias_estimator.sparsity == 0.25


def test_reference_point_rejects_bad_anchors_and_ranges() -> None:
    msg = "z: expected finite ranges >= 0 (m), got {} at row {}"
    for z, shown, row in [
        ([5.0, -1.0, 6.0], "-1", 1),
        ([5.0, 6.0, np.inf], "inf", 2),
        ([np.nan, 6.0, 7.0], "nan", 0),
        ([5.0, 6.0, -np.inf], "-inf", 2),
    ]:
        with pytest.raises(ValueError, match=exact(msg.format(shown, row))):
            mitigation.reference_point(ANCHORS, np.array(z))
    with pytest.raises(ValueError, match=exact("z: expected shape (3, 1), got (2, 1)")):
        mitigation.reference_point(ANCHORS, np.array([5.0, 6.0]))
    with pytest.raises(
        ValueError, match=exact("anchors: expected at least 2 anchors (rows), got 1")
    ):
        mitigation.reference_point(ANCHORS[:1], np.array([5.0]))
    bad = ANCHORS.copy()
    bad[1, 0] = np.nan
    with pytest.raises(ValueError, match=exact("anchors: expected finite values (no NaN or inf)")):
        mitigation.reference_point(bad, EXACT)
    # two anchors and a zero range are valid: circles of radius 6 around (0, 0) and (10, 0) meet at
    # (5, +-sqrt(11)); a zero range is a point disc, tangent to the other circle here
    two = mitigation.reference_point(ANCHORS[:2], np.array([6.0, 6.0]))
    assert two.kind == mitigation.ReferenceKind.FeasibleVertices and two.vertices == 2
    np.testing.assert_allclose(two.point, [5.0, 0.0], atol=1e-12)
    zero = mitigation.reference_point(ANCHORS[:2], np.array([0.0, 10.0]))
    np.testing.assert_allclose(zero.point, [0.0, 0.0], atol=1e-12)
    # BiasEstimator.estimate still takes a negative range (noise near an anchor)
    e = mitigation.BiasEstimator(ANCHORS).estimate(EXACT - np.array([5.5, 0, 0]), np.ones(3))
    assert np.all(np.isfinite(e.bias))


def estimator_views(est):
    """What an estimate may change: the last estimate and the exposed intermediates."""
    last, v = est.last, est
    views = [last.bias, last.upper, last.flags, v.sigma_v, v.sigma_v_ginv, v.qp_hessian]
    return views + [v.qp_gradient, v.r, v.L]


def test_d_of_eq_27_must_be_a_covariance_and_a_refusal_changes_nothing() -> None:
    est = mitigation.BiasEstimator(ANCHORS)
    z = np.full(3, 20.0)
    d = np.array([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]])
    assert est.estimate_from_innovation(z, np.array([1.0, -1.0, 0.0]), d).qp.ok()
    views = estimator_views(est)
    innov = np.array([5.0, 3.0, 1.0])
    pd = "D: expected a positive definite matrix (eq. 27: F P F^T + R), got the pivot {} at row {} "
    pd += "of its Cholesky factorisation"
    asym = d.copy()
    asym[0, 1], asym[1, 0] = 1.5, -1.5
    with pytest.raises(
        ValueError, match=exact("D: expected a symmetric matrix, got D[0,1] = 1.5 != D[1,0] = -1.5")
    ):
        est.estimate_from_innovation(z, innov, asym)  # was silently symmetrised
    for bad in [np.inf, -np.inf, np.nan]:
        dd = d.copy()
        dd[2, 2] = bad
        with pytest.raises(ValueError, match=exact("D: expected finite values (no NaN or inf)")):
            est.estimate_from_innovation(z, innov, dd)  # inf was DEGENERATE_GEOMETRY (flags 8)
    indef = np.eye(3)
    indef[0, 1] = indef[1, 0] = 2.0
    for dd, pivot, row in [(-np.eye(3), "-1", 0), (indef, "-3", 1), (np.diag([1.0, 0, 1]), "0", 1)]:
        with pytest.raises(ValueError, match=exact(pd.format(pivot, row))):
            est.estimate_from_innovation(z, innov, dd)
    with pytest.raises(ValueError, match=r"^D: expected a symmetric matrix"):
        est.estimate_from_innovation(np.array([20.0, np.nan, 20.0]), innov, asym)  # even then
    after = estimator_views(est)
    for a, b in zip(views, after, strict=True):
        np.testing.assert_array_equal(a, b)
    # round-off asymmetry (1e-12 of max |D|, as F P F^T + R in floating point) passes
    near = d.copy()
    near[0, 1] += 2e-12
    e = est.estimate_from_innovation(z, np.array([1.0, -1.0, 0.0]), near)
    assert e.qp.ok() and e.flags == 0
    np.testing.assert_allclose(e.bias, [1.5, 0.0, 0.0], atol=1e-6)


def test_soft_threshold_hand_computed() -> None:
    # D = diag(1, 4, 9), lambda = 2: b = clip(r - 2 sqrt(D_ii), 0, b^U) (the C++ test's case).
    est = mitigation.BiasEstimator(ANCHORS)
    est.soft_threshold = 2.0
    z = np.full(3, 20.0)
    e = est.estimate_from_innovation(z, np.array([5.0, 3.0, 40.0]), np.diag([1.0, 4.0, 9.0]))
    np.testing.assert_allclose(e.bias, [3.0, 0.0, 40.0 - np.sqrt(200.0)], atol=1e-6)
    with pytest.raises(ValueError, match="soft_threshold: expected a finite value >= 0"):
        est.soft_threshold = -1.0
    assert est.soft_threshold == 2.0
    # In the tracker: a LOS row with a small positive innovation is kept (b^ = 0), not dropped.
    opt = mitigation.QpBiasEkfOptions()
    assert opt.soft_threshold == 0.0
    opt.noise = mitigation.RangeNoise(1.0)
    opt.always_estimate = True
    mean, cov = np.array([3.0, 4.0, 0.0, 0.0]), np.eye(4)
    y = EXACT + np.array([0.5, 0.0, 3.0])
    plain = mitigation.QpBiasEkf(motion(), ANCHORS, mean, cov, opt).update(y)
    opt.soft_threshold = 2.0
    f = mitigation.QpBiasEkf(motion(), ANCHORS, mean, cov, opt)
    soft = f.update(y)
    assert plain.rows_dropped == 2 and soft.rows_dropped < plain.rows_dropped
    assert f.bias[0] == pytest.approx(0.0, abs=1e-6)
    opt.soft_threshold = -0.5
    with pytest.raises(ValueError, match="options.soft_threshold: expected a finite value >= 0"):
        mitigation.QpBiasEkf(motion(), ANCHORS, mean, cov, opt)


def test_innovation_test_eqs_31_32() -> None:
    opt = mitigation.QpBiasEkfOptions()
    opt.noise = mitigation.RangeNoise(1.0)
    mean, cov = np.array([3.0, 4.0, 0.0, 0.0]), np.eye(4)
    f = mitigation.QpBiasEkf(motion(), ANCHORS, mean, cov, opt)
    s = f.update(EXACT + 1.0)
    assert s.threshold == pytest.approx(6.6) and s.innovation_sq == pytest.approx(3.0)
    assert not s.nlos and not s.bias_estimated
    g = mitigation.QpBiasEkf(motion(), ANCHORS, mean, cov, opt)
    s = g.update(EXACT + np.array([0, 0, 3.0]))
    assert s.nlos and s.bias_estimated and g.nlos_detected and g.bias.sum() > 0
    assert isinstance(s.filter.log_likelihood, float)


def test_qp_failure_keeps_a_finite_state() -> None:
    opt = mitigation.QpBiasEkfOptions()
    opt.always_estimate = True
    opt.noise = mitigation.RangeNoise(0.5)
    mean, cov = np.array([2.5, 4.5, 0, 0]), np.eye(4)
    f = mitigation.QpBiasEkf(motion(), ANCHORS, mean, cov, opt, solver="failing")
    s = f.update(EXACT + np.array([0, 3.0, 0]))
    assert s.flags & mitigation.FLAG_QP_FAILED
    assert np.all(np.isfinite(f.mean)) and np.all(f.bias == 0)
    with pytest.raises(ValueError, match="gamma"):
        bad = mitigation.QpBiasEkfOptions()
        bad.gamma = 0.2
        mitigation.QpBiasEkf(motion(), ANCHORS, mean, cov, bad)


def k1_track(rng: np.random.Generator, steps: int, nlos: np.ndarray):
    x = np.array([1000.0, 1000.0, 10.0, 15.0])
    truth, z = [], []
    for k in range(steps):
        if k:
            a = rng.normal(size=2)
            x = np.array(
                [
                    x[0] + 0.1 * x[2] + 0.005 * a[0],
                    x[1] + 0.1 * x[3] + 0.005 * a[1],
                    x[2] + 0.1 * a[0],
                    x[3] + 0.1 * a[1],
                ]
            )
        d = np.linalg.norm(x[:2] - K1_ANCHORS, axis=1)
        truth.append(x[:2].copy())
        z.append(d + rng.normal(0, 50, 3) + nlos * rng.normal(513, 436, 3))
    return np.array(truth), np.array(z)


def test_trackers_on_a_k1_like_track() -> None:
    rng = np.random.default_rng(11)
    truth, z = k1_track(rng, 800, np.ones(3))
    mean = np.array([1000.0, 1000.0, 10.0, 15.0]) + rng.normal(0, [50, 50, 10, 10])
    cov = np.diag([50.0**2, 50.0**2, 100.0, 100.0])
    opt = mitigation.QpBiasEkfOptions()
    prop = mitigation.QpBiasEkf(motion(), K1_ANCHORS, mean, cov, opt)
    plain_opt = mitigation.QpBiasEkfOptions()
    plain_opt.mitigate = False
    plain = mitigation.QpBiasEkf(motion(), K1_ANCHORS, mean, cov, plain_opt)
    ep = np.linalg.norm(prop.run(z)[100:, :2] - truth[100:], axis=1)
    ee = np.linalg.norm(plain.run(z)[100:, :2] - truth[100:], axis=1)
    assert np.percentile(ep, 67) < 0.8 * np.percentile(ee, 67)
    aug = mitigation.BiasAugmentedEkf(motion(), K1_ANCHORS, mean, cov)
    assert aug.state_dim == 7
    for k in range(200):
        (aug.update if k == 0 else aug.step)(z[k])
    assert np.all(np.isfinite(aug.mean)) and np.all(aug.bias >= 0)
    assert aug.kinematic_mean.shape == (4,)
