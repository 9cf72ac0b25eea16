"""A box-QP solver written in Python behind QpBiasEkf and BiasEstimator (solver=<object>): the
same numbers as the built-in solver it wraps, an osqp one close to the default, the failure and
error paths with the tracker unchanged, and copies for the Monte Carlo workers."""

from __future__ import annotations

import re

import numpy as np
import pytest

from box_qp_helpers import Enumeration, osqp_box
from nlosloc import mitigation, models, sim

K1_ANCHORS = np.array([[0.0, 0.0], [8600.0, 0.0], [4300.0, 7500.0]])


def motion() -> models.ConstantVelocity2:
    return models.ConstantVelocity2(0.1, 1.0, models.VelocityNoise.WhiteAcceleration)


class Osqp:
    """osqp on the same box QP."""

    def solve(self, H, g, lower, upper):  # noqa: N803
        r = osqp_box(H, g, lower, upper, 1e-10, 100000)
        return None if r.x is None or not np.all(np.isfinite(r.x)) else np.clip(r.x, lower, upper)


class Returns:
    """solve() returns a fixed object (or raises it) after `ok` good calls."""

    def __init__(self, result, ok: int = 0) -> None:
        self.result, self.ok, self.inner = result, ok, Enumeration()

    def solve(self, H, g, lower, upper):  # noqa: N803
        if self.ok > 0:
            self.ok -= 1
            return self.inner.solve(H, g, lower, upper)
        if isinstance(self.result, Exception):
            raise self.result
        return self.result(len(g)) if callable(self.result) else self.result


def exact(msg: str) -> str:
    """A pytest.raises match for exactly this message."""
    return "^" + re.escape(msg) + "$"


def estimator_view(e: mitigation.BiasEstimator) -> list:
    """Everything a BiasEstimator shows: its intermediates (eqs. 9-14) and its last estimate."""
    last = e.last
    return [
        e.H0,
        e.U,
        e.L,
        e.y,
        e.r,
        e.sigma_v,
        e.sigma_v_ginv,
        e.qp_hessian,
        e.qp_gradient,
        last.bias,
        last.lower,
        last.upper,
        last.x_tilde,
        last.reference.point,
        last.flags,
        last.qp.status,
        last.qp.iterations,
    ]


def assert_same_view(before: list, after: list) -> None:
    for a, b in zip(before, after, strict=True):
        np.testing.assert_array_equal(a, b)


def k1_ranges(steps: int, seed: int = 3) -> np.ndarray:
    d = sim.K1().draw("1LOS/2NLOS", seed, 0, steps)
    return d["y"]


def tracker(solver, always: bool = True) -> mitigation.QpBiasEkf:
    o = mitigation.QpBiasEkfOptions()
    o.always_estimate = always
    mean = np.array([1000.0, 1000.0, 10.0, 15.0])
    return mitigation.QpBiasEkf(
        motion(), K1_ANCHORS, mean, np.diag([2500.0, 2500, 100, 100]), o, solver
    )


def test_a_python_solver_gives_the_numbers_of_the_solver_it_wraps() -> None:
    z = k1_ranges(300)
    mine = Enumeration()
    f, g = tracker(mine), tracker("enumeration")
    assert f.solver_name == "py-enumeration"
    np.testing.assert_array_equal(f.run(z), g.run(z))  # run() releases the GIL: the solver takes it
    assert mine.calls == 300  # always_estimate: one QP per step
    np.testing.assert_array_equal(f.bias, g.bias)
    # BiasEstimator likewise
    e, ref = (
        mitigation.BiasEstimator(K1_ANCHORS, Enumeration()),
        mitigation.BiasEstimator(K1_ANCHORS, "enumeration"),
    )
    for k in range(0, 300, 30):
        np.testing.assert_array_equal(
            e.estimate(z[k], np.full(3, 2500.0)).bias, ref.estimate(z[k], np.full(3, 2500.0)).bias
        )
    assert mitigation.BiasEstimator(K1_ANCHORS, Osqp()).solver_name == "Osqp"  # the class name


def test_an_osqp_solver_tracks_as_the_default() -> None:
    pytest.importorskip("osqp")
    z = k1_ranges(200)
    xo, xd = tracker(Osqp()).run(z), tracker("default").run(z)
    # eq. (14) with the prediction reference is strictly convex: one minimiser, to osqp's tolerance
    assert np.max(np.abs(xo[:, :2] - xd[:, :2])) < 1e-3


@pytest.mark.parametrize(
    ("result", "error", "match"),
    [
        (np.zeros(2), ValueError, r"solve\(\) of 'Returns' returned an array of shape \(2,\); "),
        ("abc", ValueError, r"returned an object of type str; expected the 3 values"),
        (lambda n: np.full(n, -1.0), ValueError, r"returned x\[0\] = -1.0 outside \[0.0, "),
        # numpy cast these to float64 (the imaginary part dropped with a warning, True as 1.0)
        (
            lambda n: np.full(n, 1.0 + 0j),
            ValueError,
            r"^solver: solve\(\) of 'Returns': expected real values, got a complex array$",
        ),
        (lambda n: np.ones(n, bool), ValueError, r"^solver: solve\(\) of 'Returns': expected real"),
        (ZeroDivisionError("inside"), ZeroDivisionError, "inside"),
    ],
)
def test_a_bad_result_or_an_exception_leaves_the_tracker_unchanged(result, error, match) -> None:
    z = k1_ranges(5)
    f = tracker(Returns(result, ok=2))
    f.update(z[0])
    f.step(z[1])
    before = (f.mean.copy(), f.cov.copy(), f.time, f.bias.copy(), f.last_step.flags)
    view = estimator_view(f.bias_estimator)
    with pytest.raises(error, match=match):
        f.step(z[2])
    with pytest.raises(error, match=match):
        f.update(z[2])
    with pytest.raises(error, match=match):
        f.run(z[2:4], first_is_update=False)
    after = (f.mean, f.cov, f.time, f.bias, f.last_step.flags)
    for a, b in zip(before, after):
        np.testing.assert_array_equal(a, b)
    # the estimator's intermediates as well (they kept the rejected call's values)
    assert_same_view(view, estimator_view(f.bias_estimator))


class Raise:
    """A solver that raises."""

    def solve(self, H, g, lower, upper):  # noqa: N803
        raise RuntimeError("boom")


@pytest.mark.parametrize("reference", ["Prediction", "Snapshot"])
def test_a_raising_solver_leaves_the_whole_tracker_unchanged(reference: str) -> None:
    # The checker's reproducer: four anchors, a bias estimate at every step.
    a4 = np.array([[0.0, 0], [1000, 0], [1000, 1000], [0, 1000.0]])
    z = np.array([631.0, 788, 779, 750.0])
    o = mitigation.QpBiasEkfOptions()
    o.always_estimate = True
    o.reference = getattr(mitigation.BiasReference, reference)
    m0, p0 = np.array([400.0, 500, 3, 2]), np.diag([400.0, 400, 4, 4])
    cv = models.ConstantVelocity2(1.0, 0.5, models.VelocityNoise.WhiteAcceleration)
    f = mitigation.QpBiasEkf(cv, a4, m0, p0, o, solver=Raise())
    view = estimator_view(f.bias_estimator)
    with pytest.raises(RuntimeError, match="^boom$"):
        f.step(z)
    with pytest.raises(RuntimeError, match="^boom$"):
        f.update(z + 10.0)
    assert_same_view(view, estimator_view(f.bias_estimator))
    np.testing.assert_array_equal(f.mean, m0)
    np.testing.assert_array_equal(f.cov, p0)
    assert f.time == 0.0
    # after a successful estimate too (the intermediates are not the initial zeros then)
    once = Returns(RuntimeError("boom"), ok=1)
    once.inner = Enumeration(4)
    g = mitigation.QpBiasEkf(cv, a4, m0, p0, o, solver=once)
    g.update(z)
    assert g.last_step.bias_estimated
    view = estimator_view(g.bias_estimator)
    assert np.any(view[7] != 0.0)  # qp_hessian
    with pytest.raises(RuntimeError, match="^boom$"):
        g.step(z + 5.0)
    assert_same_view(view, estimator_view(g.bias_estimator))


def test_a_raising_solver_leaves_a_bare_estimator_unchanged() -> None:
    z = k1_ranges(3)
    var = np.full(3, 2500.0)
    e = mitigation.BiasEstimator(K1_ANCHORS, Returns(RuntimeError("boom"), ok=1))
    e.estimate(z[0], var)
    assert e.last.qp.ok()
    view = estimator_view(e)
    with pytest.raises(RuntimeError, match="^boom$"):
        e.estimate(z[1], var)  # would change H0, U and y (eqs. 9-11) and the rest
    assert_same_view(view, estimator_view(e))
    with pytest.raises(RuntimeError, match="^boom$"):
        e.estimate_from_innovation(
            z[1], np.array([100.0, -50.0, 20.0]), np.diag([2500.0, 2600, 2700])
        )
    assert_same_view(view, estimator_view(e))
    # out of the box: the same (ValueError naming the solver)
    out = mitigation.BiasEstimator(K1_ANCHORS, Returns(lambda n: np.full(n, -1.0), ok=1))
    out.estimate(z[0], var)
    view = estimator_view(out)
    with pytest.raises(ValueError, match=r"returned x\[0\] = -1.0 outside"):
        out.estimate(z[1], var)
    assert_same_view(view, estimator_view(out))


BUILT_IN = ["enumeration", "failing"] + (["proxsuite"] if mitigation.have_proxsuite_box_qp else [])


@pytest.mark.parametrize("name", BUILT_IN)
def test_built_in_solvers_refuse_a_non_symmetric_or_indefinite_h(name: str) -> None:
    q = mitigation.make_box_qp(3, solver=name)
    lo, up, g = -np.ones(3), np.ones(3), np.array([1.0, -1.0, 0.5])
    # a valid problem first: x = (-1, 0.5, -0.25) (0 for 'failing')
    q.solve(np.eye(3), np.array([2.0, -0.5, 0.25]), lo, up)
    x = q.x
    # The checker's reproducer: proxsuite said Solved, objective 0.125; the box minimum is -1.875.
    with pytest.raises(
        ValueError,
        match=exact(
            "H: expected a positive semidefinite matrix, got negative curvature -1 at row 1 "
            "(pivoted Cholesky)"
        ),
    ):
        q.solve(np.diag([2.0, -1, 1]), g, lo, up)
    coupled = np.array([[1.0, 0, 0], [0, 0, 2], [0, 2, 0]])  # block [0 2; 2 0]: eigenvalue -2
    with pytest.raises(
        ValueError,
        match=exact(
            "H: expected a positive semidefinite matrix, got negative curvature -2 at rows 1, 2 "
            "(pivoted Cholesky)"
        ),
    ):
        q.solve(coupled, g, lo, up)
    asym = np.array([[2.0, 1.5, 0], [-1.5, 1, 0], [0, 0, 1]])  # proxsuite read one triangle
    with pytest.raises(
        ValueError, match=exact("H: expected a symmetric matrix, got H[0,1] = 1.5 != H[1,0] = -1.5")
    ):
        q.solve(asym, g, lo, up)
    np.testing.assert_array_equal(q.x, x)  # the refused calls left the last minimiser
    if name == "enumeration":
        assert q.active_set == [1, 0, 0]
    # within the tolerances: asymmetry 1e-11 of max |H|, a pivot -1e-13 >= -3 1e-12 max diag
    near = np.eye(3)
    near[0, 2], near[2, 0] = 0.25 + 1e-11, 0.25
    q.solve(near, g, lo, up)
    q.solve(np.diag([1.0, -1e-13, 1.0]), g, lo, up)
    with pytest.raises(
        ValueError, match=r"^H: expected a positive semidefinite .* -1e-11 at row 1 "
    ):
        q.solve(np.diag([1.0, -1e-11, 1.0]), g, lo, up)


@pytest.mark.parametrize("name", [n for n in BUILT_IN if n != "failing"])
def test_rank_deficient_psd_problems_solve_to_the_scipy_minimum(name: str) -> None:
    from scipy.optimize import minimize

    lo, up, g = np.array([-1.0, 0.0, -2.0]), np.array([1.0, 2.0, 0.5]), np.array([1.0, -1.0, 0.5])
    v = np.array([1.0, 2.0, -1.0])
    a = np.random.default_rng(5).normal(size=(3, 2))
    q = mitigation.make_box_qp(3, solver=name)
    for h in [np.zeros((3, 3)), np.outer(v, v), np.diag([2.0, 0.0, 1.0]), a @ a.T]:
        r = q.solve(h, g, lo, up)
        assert r.ok()

        def f(x, h=h):
            return 0.5 * x @ h @ x + g @ x, h @ x + g

        ref = minimize(
            f,
            np.zeros(3),
            jac=True,
            method="L-BFGS-B",
            bounds=list(zip(lo, up, strict=True)),
            options={"ftol": 1e-15, "gtol": 1e-12},
        )
        assert r.objective == pytest.approx(ref.fun, abs=1e-7)
        assert r.objective == pytest.approx(0.5 * q.x @ h @ q.x + g @ q.x, abs=1e-12)


def test_none_or_nan_is_a_failure_and_the_tracker_falls_back() -> None:
    z = k1_ranges(3)
    for result in [None, lambda n: np.full(n, np.nan)]:
        f = tracker(Returns(result))
        s = f.update(z[0])
        assert s.flags & mitigation.FLAG_QP_FAILED
        np.testing.assert_array_equal(f.bias, np.zeros(3))  # no bias subtracted
        assert np.all(np.isfinite(f.mean))


def test_an_object_without_solve_is_refused() -> None:
    with pytest.raises(TypeError, match=r"solver: expected a solver name \(str\) or an object"):
        tracker(object())
    with pytest.raises(TypeError, match="object with a method solve"):
        mitigation.BiasEstimator(K1_ANCHORS, 3)


def test_monte_carlo_workers_run_copies_of_a_tracker_with_a_python_solver() -> None:
    s = sim.K1()
    p = s.params
    o = mitigation.QpBiasEkfOptions()
    o.gamma = p.gamma
    o.noise.sigma0 = p.sigma_los
    mine = Enumeration()
    qp = mitigation.QpBiasEkf(s.motion, p.anchors, np.zeros(4), np.eye(4), o, mine)
    res = sim.run_monte_carlo(
        "K1", "1LOS/2NLOS", 4, 7, ["proposed", ("py-qp", qp)], threads=2, steps=200
    )
    e = res["estimators"]
    np.testing.assert_array_equal(e["py-qp"]["errors"], e["proposed"]["errors"])
    assert mine.calls == 0  # the workers' copies (copy.deepcopy) solved, not the object given


def test_built_in_solvers_copy() -> None:
    import copy

    names = ["enumeration", "failing"] + (["proxsuite"] if mitigation.have_proxsuite_box_qp else [])
    h, g = np.diag([2.0, 1.0, 4.0]), np.array([-2.0, 3.0, -1.0])
    lo, up = np.zeros(3), np.ones(3)
    for name in names:
        q = mitigation.make_box_qp(3, solver=name)
        for make in [lambda q: q.clone(), copy.copy, copy.deepcopy]:
            q.solve(h, g, lo, up)
            c = make(q)
            assert c is not q and c.name == q.name
            np.testing.assert_array_equal(c.x, q.x)
            assert c.solve(h, -g, lo, up).status == q.solve(h, -g, lo, up).status
            np.testing.assert_array_equal(c.x, q.x)
