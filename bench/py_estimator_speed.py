"""Time per step of the kinds of estimators the Monte Carlo runner takes from Python, on K1
(2000 steps per run): the registered EKF, the same EKF given as a filter object (native), a Python
estimator that does nothing (the call overhead alone) and the same EKF written as a Python
estimator around nlosloc.filters.

Usage: .venv/bin/python bench/py_estimator_speed.py [--runs 20] [--threads 1 2]
Prints, per thread count, the run's wall time and each estimator's median time_per_step_ns.
"""

import argparse

import numpy as np

from nlosloc import filters, sim


class Nothing:
    def reset(self, draw, rng):
        pass

    def step(self, k, y, o):
        return np.zeros(2)


class PythonEkf:
    def __init__(self, scenario, case_index):
        self.f = filters.Ekf(scenario.motion, scenario.measurements, np.zeros(4), np.eye(4))

    def reset(self, draw, rng):
        self.f.set_belief(draw["initial_mean"], draw["initial_cov"], 0.0)

    def step(self, k, y, o):
        if k > 0:
            self.f.step(y)
        else:
            self.f.update(y)
        return self.f.mean[:2]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    a = ap.parse_args()
    k1 = sim.K1()
    entries = [
        "EKF",
        (
            "EKF as a filter (native)",
            filters.Ekf(k1.motion, k1.measurements, np.zeros(4), np.eye(4)),
        ),
        ("Python: nothing", lambda s, c: Nothing()),
        ("Python: EKF", PythonEkf),
    ]
    for t in a.threads:
        res = sim.run_monte_carlo("K1", "2LOS/1NLOS", a.runs, 1, entries, threads=t)
        print(
            f"{t} thread(s), {a.runs} runs x {res['steps']} steps, {res['wall_seconds']:.2f} s wall"
        )
        for name, e in res["estimators"].items():
            print(f"  {name:28s} {np.median(e['time_per_step_ns']) / 1000.0:8.3f} us/step")


if __name__ == "__main__":
    main()
