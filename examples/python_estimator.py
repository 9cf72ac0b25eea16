"""A tracker written in Python, compared with the registered ones on the same Monte Carlo draws.

The tracker is an EKF that gates each range by its innovation (a classic NLOS defence, not in the
papers): a row whose residual exceeds `gate` standard deviations of its predicted spread is treated
as missing for that step. It runs beside the registered K1 estimators through
nlosloc.montecarlo.run(estimators=[..., (name, factory)]), and the table is the bench's.

    .venv/bin/python examples/python_estimator.py [--runs 100] [--case 2LOS/1NLOS] [--gate 3]
"""

from __future__ import annotations

import argparse

import numpy as np

from nlosloc import core, filters, montecarlo, sim


class GatedEkf:
    """EKF with LOS noise that skips the rows whose innovation is beyond `gate` sigmas."""

    def __init__(self, scenario: sim.Scenario, case_index: int, gate: float = 3.0) -> None:
        self.meas = scenario.measurements
        self.ekf = filters.Ekf(scenario.motion, self.meas, np.zeros(4), np.eye(4))
        self.gate = gate
        self.los = np.zeros(self.meas.num_anchors, dtype=int)

    def reset(self, draw: dict, rng: core.Rng) -> None:
        self.ekf.set_belief(draw["initial_mean"], draw["initial_cov"], 0.0)

    def step(self, k: int, y: np.ndarray, o: np.ndarray) -> np.ndarray:
        if k > 0:
            self.ekf.predict()  # the initial belief is already at t_0
        x, P = self.ekf.mean, self.ekf.cov
        H = self.meas.jacobian(x, self.ekf.time)
        _, R = self.meas.noise_moments(x, self.los)
        S = H @ P @ H.T + R
        r = self.meas.residual(y, self.meas.predict(x, self.ekf.time))
        y = np.where(np.abs(r) > self.gate * np.sqrt(np.diag(S)), np.nan, y)
        if not np.all(np.isnan(y)):
            self.ekf.update(y)
        return self.ekf.mean[:2]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--case", default="2LOS/1NLOS")
    ap.add_argument("--gate", type=float, default=3.0)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    name = f"gated-EKF-{a.gate:g}"
    result = montecarlo.run(
        "K1",
        a.case,
        a.runs,
        a.seed,
        ["EKF", "proposed", (name, lambda s, c: GatedEkf(s, c, a.gate))],
        progress=False,
    )
    print(sim.format_table(sim.summarize("K1", result)))


if __name__ == "__main__":
    main()
