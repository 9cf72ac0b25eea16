"""Time per step of K1's proposed tracker (QpBiasEkf, a QP at every step) with the built-in
enumeration solver and with solvers written in Python: the same enumeration called through Python
(the cost of the call alone) and osqp (if installed), over one K1 draw (QpBiasEkf.run, GIL released
except inside the Python solver).

Usage: .venv/bin/python bench/py_box_qp_speed.py [--steps 2000] [--repeat 5]
Prints each solver's best time per step (us) over the repeats and its largest position difference
from the built-in solver (m).
"""

import argparse
import time

import numpy as np
import scipy.sparse as sp

from nlosloc import mitigation, sim


class PyEnumeration:
    """The built-in enumeration solver, called from Python."""

    def __init__(self, n):
        self.qp = mitigation.make_box_qp(n, solver="enumeration")

    def solve(self, H, g, lower, upper):  # noqa: N803
        return self.qp.x if self.qp.solve(H, g, lower, upper).ok() else None


class Osqp:
    def solve(self, H, g, lower, upper):  # noqa: N803
        import osqp

        prob = osqp.OSQP()
        prob.setup(
            P=sp.csc_matrix(np.triu(H)),
            q=g,
            A=sp.identity(len(g), format="csc"),
            l=lower,
            u=upper,
            eps_abs=1e-10,
            eps_rel=1e-10,
            polishing=False,
            verbose=False,
        )
        r = prob.solve(raise_error=False)
        return None if r.x is None else np.clip(r.x, lower, upper)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    k1 = sim.K1()
    d = k1.draw("1LOS/2NLOS", 1, 0, a.steps)
    z, m0, p0 = d["y"], d["initial_mean"], d["initial_cov"]
    o = mitigation.QpBiasEkfOptions()
    o.gamma, o.noise.sigma0, o.always_estimate = k1.params.gamma, k1.params.sigma_los, True
    solvers = {"enumeration (C++)": "enumeration", "enumeration via Python": PyEnumeration(3)}
    try:
        import osqp  # noqa: F401

        solvers["osqp via Python"] = Osqp()
    except ImportError:
        pass
    ref = None
    print(f"K1 1LOS/2NLOS, {a.steps} steps, a QP at every step (always_estimate)")
    for name, solver in solvers.items():
        best = np.inf
        for _ in range(a.repeat):
            f = mitigation.QpBiasEkf(k1.motion, k1.params.anchors, m0, p0, o, solver)
            t0 = time.perf_counter()
            x = f.run(z)
            best = min(best, time.perf_counter() - t0)
        ref = x if ref is None else ref
        diff = np.max(np.abs(x[:, :2] - ref[:, :2]))
        print(f"{name:26s} {1e6 * best / a.steps:9.2f} us/step   max |dx| {diff:.2e} m")


if __name__ == "__main__":
    main()
