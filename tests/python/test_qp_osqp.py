"""The box-QP solvers against the osqp package on 1000 random box-constrained least-squares
problems of 3 to 10 variables with PSD rank-deficient Hessians shaped like Ke & Wu's
L^T Sigma_v^- L (eq. 14): objectives to 1e-6 relative, minimisers to 1e-4 where the minimiser is
unique. "default" is make_box_qp's solver (proxsuite), "enumeration" ours (up to 8 variables)."""

from __future__ import annotations

import numpy as np
import pytest

osqp = pytest.importorskip("osqp")
from box_qp_helpers import osqp_box  # noqa: E402
from nlosloc import mitigation  # noqa: E402


def ke_wu_hessian(rng: np.random.Generator, n: int) -> np.ndarray:
    """2 L^T (R^-1 L) L, L = I - H0 (H0^T R^-1 H0)^-1 H0^T R^-1: PSD, rank n - 2 (eqs. 11-13)."""
    ang = rng.uniform(0, 2 * np.pi, n)
    h0 = np.column_stack([np.cos(ang), np.sin(ang)])
    rinv = np.diag(1.0 / rng.uniform(0.5, 2.0, n))
    u = -np.linalg.solve(h0.T @ rinv @ h0, h0.T @ rinv)
    lm = np.eye(n) + h0 @ u
    h = 2.0 * lm.T @ (rinv @ lm) @ lm
    return 0.5 * (h + h.T)


def random_problem(rng: np.random.Generator):
    n = int(rng.integers(3, 11))
    if rng.random() < 0.7:
        h = ke_wu_hessian(rng, n)
    else:  # generic PSD of random rank 1..n-1
        k = int(rng.integers(1, n))
        a = rng.normal(size=(k, n))
        h = a.T @ a
    b_true = rng.exponential(2.0, n) * (rng.random(n) < 0.6)
    noise = rng.normal(scale=0.5, size=n)
    # Half the problems have g in the range of H, as eq. (14)'s (g = -2 L^T Sigma_v^- r): then the
    # minimiser is generally not unique; the others get a component outside it (pushes to the box).
    r = h @ (b_true + noise) if rng.random() < 0.5 else h @ b_true + noise
    g = -r
    lower = np.zeros(n) if rng.random() < 0.7 else -rng.uniform(0, 3, n)
    upper = lower + rng.uniform(0.1, 6.0, n)
    return h, g, lower, upper


def objective(h: np.ndarray, g: np.ndarray, x: np.ndarray) -> float:
    return float(0.5 * x @ h @ x + g @ x)


def solve_osqp(h, g, lower, upper) -> np.ndarray:
    res = osqp_box(h, g, lower, upper, 1e-11, 200000)
    assert res.info.status in ("solved", "solved inaccurate"), res.info.status
    return np.clip(np.asarray(res.x), lower, upper)


def minimiser_is_unique(h, g, lower, upper, x, tol=1e-7) -> bool:
    """Unique when H is positive definite on the variables not held by a strongly active bound."""
    grad = h @ x + g
    at_low = (x - lower < 1e-7) & (grad > tol)
    at_up = (upper - x < 1e-7) & (grad < -tol)
    free = ~(at_low | at_up)
    if not free.any():
        return True
    hs = h[np.ix_(free, free)]
    return bool(np.linalg.eigvalsh(hs).min() > 1e-6 * max(1.0, np.abs(h).max()))


@pytest.mark.parametrize("solver", ["default", "enumeration"])
def test_box_qp_matches_osqp_on_1000_problems(solver: str) -> None:
    if solver == "default" and not mitigation.have_proxsuite_box_qp:
        pytest.skip("nlosloc built without proxsuite (needed above 8 variables)")
    rng = np.random.default_rng(20110127)
    # the enumeration takes n <= 8: problems of 9 and 10 variables are drawn and skipped
    solvers = {
        n: mitigation.make_box_qp(n, solver=solver)
        for n in range(3, 11)
        if solver == "default" or n <= 8
    }
    unique = 0
    worst_obj = 0.0
    worst_x = 0.0
    for _ in range(1000):
        h, g, lower, upper = random_problem(rng)
        if len(g) not in solvers:
            continue
        qp = solvers[len(g)]
        res = qp.solve(h, g, lower, upper)
        assert res.ok(), res.status
        x = qp.x
        assert np.all(x >= lower) and np.all(x <= upper)
        xo = solve_osqp(h, g, lower, upper)
        f, fo = objective(h, g, x), objective(h, g, xo)
        assert res.objective == pytest.approx(f, rel=1e-12, abs=1e-12)
        rel = abs(f - fo) / max(1.0, abs(fo))
        worst_obj = max(worst_obj, rel)
        assert rel <= 1e-6, (f, fo)
        if minimiser_is_unique(h, g, lower, upper, xo):
            unique += 1
            err = float(np.abs(x - xo).max())
            worst_x = max(worst_x, err)
            assert err <= 1e-4, (x, xo)
    assert 100 <= unique < 1000  # both kinds present: unique and non-unique minimisers
    print(
        f"unique minimisers: {unique}/1000, worst objective rel diff {worst_obj:.2e}, "
        f"worst x {worst_x:.2e}"
    )
