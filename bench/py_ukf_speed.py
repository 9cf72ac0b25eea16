"""Per-step time of nlosloc's UKF run from Python over a (200, 3) array in one call, against
FilterPy's UnscentedKalmanFilter on the same model, measured in the same process (issue #2).

Usage: .venv/bin/python bench/py_ukf_speed.py [--reps N] [--json FILE]
"""

import argparse
import json
import statistics
import sys
import time

import numpy as np

from nlosloc import core, filters, models, noise

ANCHORS = np.array([[0.0, 0.0], [8600.0, 0.0], [4300.0, 7500.0]])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=200, help="timed repetitions of the nlosloc run")
    ap.add_argument("--filterpy-reps", type=int, default=5, help="timed repetitions of FilterPy")
    ap.add_argument("--json", help="write the figures to this file")
    a = ap.parse_args()
    from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

    motion = models.ConstantVelocity2(0.1, 1.0, models.VelocityNoise.WhiteAcceleration)
    rng = np.random.default_rng(1)
    x = np.array([1000.0, 1000.0, 10.0, 15.0])
    Y = []
    for _ in range(200):
        x = motion.F @ x
        Y.append(np.linalg.norm(x[:2] - ANCHORS, axis=1) + 50 * rng.standard_normal(3))
    Y = np.array(Y)
    x0, P0 = np.array([1000.0, 1000.0, 10.0, 15.0]), np.diag([2500.0, 2500.0, 100.0, 100.0])
    st = models.MeasurementStack(models.ConstantVelocity2.layout(), ANCHORS, 1)
    for b in range(3):
        st.add_toa(b, [noise.Normal(0.0, 50.0)])
    scheme = core.SigmaScheme.scaled(0.5, 2.0, 0.0)

    ours = []
    for _ in range(a.reps):
        f = filters.Ukf(motion, st, x0, P0, scheme)
        t0 = time.perf_counter()
        f.run(Y)
        ours.append((time.perf_counter() - t0) / len(Y))

    F = motion.F

    def fx(x, dt):
        return F @ x

    def hx(x):
        return np.linalg.norm(x[:2] - ANCHORS, axis=1)

    theirs = []
    for _ in range(a.filterpy_reps):
        pts = MerweScaledSigmaPoints(4, alpha=0.5, beta=2.0, kappa=0.0)
        u = UnscentedKalmanFilter(dim_x=4, dim_z=3, dt=0.1, hx=hx, fx=fx, points=pts)
        u.x, u.P, u.Q, u.R = x0.copy(), P0.copy(), motion.Q.copy(), 2500.0 * np.eye(3)
        t0 = time.perf_counter()
        for y in Y:
            u.predict()
            u.update(y)
        theirs.append((time.perf_counter() - t0) / len(Y))

    m_ours, m_theirs = statistics.median(ours), statistics.median(theirs)
    res = {
        "nlosloc_us_per_step_median": m_ours * 1e6,
        "filterpy_us_per_step_median": m_theirs * 1e6,
        "speedup": m_theirs / m_ours,
        "steps": len(Y),
        "reps": a.reps,
        "filterpy_reps": a.filterpy_reps,
    }
    ours_us, theirs_us = res["nlosloc_us_per_step_median"], res["filterpy_us_per_step_median"]
    print(f"nlosloc Ukf.run over (200, 3): {ours_us:.3f} us/step (median of {a.reps})")
    print(f"FilterPy UKF predict+update:  {theirs_us:.1f} us/step (median of {a.filterpy_reps})")
    print(f"speed-up: {res['speedup']:.0f}x (target >= 100x)")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(res, fh, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
