"""Box-QP solvers written in Python, shared by the tests (module level, so they pickle)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from nlosloc import mitigation


class Enumeration:
    """The built-in enumeration solver, called from Python; counts its calls."""

    name = "py-enumeration"

    def __init__(self, n: int = 3) -> None:
        self.qp = mitigation.make_box_qp(n, solver="enumeration")
        self.calls = 0

    def solve(self, H, g, lower, upper):  # noqa: N803 (the QP's names)
        self.calls += 1
        return self.qp.x if self.qp.solve(H, g, lower, upper).ok() else None


def osqp_box(h, g, lower, upper, eps: float, max_iter: int):
    """osqp's result for min 1/2 x^T h x + g^T x on lower <= x <= upper (osqp imported here: the
    callers skip when it is missing)."""
    import osqp

    prob = osqp.OSQP()
    prob.setup(
        P=sp.csc_matrix(np.triu(h)),
        q=g,
        A=sp.identity(len(g), format="csc"),
        l=lower,
        u=upper,
        eps_abs=eps,
        eps_rel=eps,
        max_iter=max_iter,
        polishing=True,
        verbose=False,
    )
    return prob.solve(raise_error=False)
