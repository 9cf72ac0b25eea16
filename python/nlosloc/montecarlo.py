"""Monte Carlo helpers around :func:`nlosloc.sim.run_monte_carlo`.

``run`` adds a progress bar (tqdm when installed, else a plain stderr line); ``percentiles``,
``ecdf`` and ``rmse`` compute the paper statistics of its result with numpy.

Examples
--------
>>> from nlosloc import montecarlo
>>> res = montecarlo.run("K1", "2LOS/1NLOS", runs=10, progress=False)
>>> montecarlo.percentiles(res, (67, 95))["EKF"]  # doctest: +SKIP
array([312.1, 380.4])
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from nlosloc._core import sim as _sim

__all__ = ["ecdf", "percentiles", "pooled_errors", "rmse", "run"]


def run(
    name: str,
    case: str,
    runs: int = 100,
    seed: int = 1,
    estimators: Sequence[str | tuple[str, Callable[[Any, int], Any]]] | None = None,
    threads: int = 0,
    steps: int | None = None,
    progress: bool | Callable[[int, int], object] = True,
) -> dict[str, Any]:
    """Run a scenario's estimators, registered or written in Python, on identical draws.

    Parameters
    ----------
    name : str
        Scenario name (see ``nlosloc.sim.scenarios()``).
    case : str
        Case name (see ``nlosloc.sim.scenario_info(name)["cases"]``).
    runs : int, default 100
        Number of runs.
    seed : int, default 1
        Seed; run r draws from ``Rng(seed, r)``.
    estimators : sequence, optional
        Registered estimator names and ``(name, factory)`` pairs of estimators written in Python
        (an object with ``reset(draw, rng)``, ``step(k, y, o) -> position`` and optionally
        ``sight_estimate()``; see :func:`nlosloc.sim.run_monte_carlo`); default all registered for
        the scenario.
    threads : int, default 0
        Worker threads (0 = every core). The result does not depend on it.
    steps : int, optional
        Steps per run; default the scenario's.
    progress : bool or callable, default True
        True shows a progress bar (tqdm if installed), False shows nothing, a callable is called as
        ``progress(done, total)``.

    Returns
    -------
    dict
        As :func:`nlosloc.sim.run_monte_carlo`: ``estimators`` maps each name to ``errors``
        (runs x T, m) and ``time_per_step_ns`` (runs); plus ``discard``, ``dt``, ``runs``,
        ``steps``, ``seed``, ``threads``, ``wall_seconds``, ``scenario``, ``case``.
    """
    est = list(estimators) if estimators is not None else None
    if callable(progress):
        return _sim.run_monte_carlo(name, case, runs, seed, est, threads, steps, progress)
    if not progress:
        return _sim.run_monte_carlo(name, case, runs, seed, est, threads, steps, None)
    bar = _Bar(total=runs, desc=f"{name} {case}")
    try:
        return _sim.run_monte_carlo(name, case, runs, seed, est, threads, steps, bar.update)
    finally:
        bar.close()


class _Bar:
    """tqdm progress bar fed with absolute counts, or a plain stderr line without tqdm."""

    def __init__(self, total: int, desc: str) -> None:
        self._done = 0
        self._desc = desc
        self._total = total
        try:
            from tqdm import tqdm
        except ImportError:
            self._tqdm = None
        else:
            self._tqdm = tqdm(total=total, desc=desc, unit="run", leave=False)

    def update(self, done: int, total: int) -> None:
        if self._tqdm is not None:
            self._tqdm.update(done - self._done)
        else:
            print(f"\r{self._desc}: {done}/{total} runs", end="", file=sys.stderr, flush=True)
        self._done = done

    def close(self) -> None:
        if self._tqdm is not None:
            self._tqdm.close()
        elif self._done:
            print(file=sys.stderr)


def pooled_errors(result: dict[str, Any], name: str, discard: bool = True) -> np.ndarray:
    """Errors of one estimator pooled over runs (and steps ``k >= discard`` when ``discard``).

    Parameters
    ----------
    result : dict
        Output of :func:`run`.
    name : str
        Estimator name.
    discard : bool, default True
        Leave out the scenario's first ``result["discard"]`` samples of every run.

    Returns
    -------
    numpy.ndarray
        1-D array of position error norms (m).
    """
    errors = np.asarray(result["estimators"][name]["errors"])
    k0 = int(result["discard"]) if discard else 0
    return errors[:, k0:].ravel()


def percentiles(
    result: dict[str, Any], q: Sequence[float] | float = (50, 67, 90, 95), discard: bool = True
) -> dict[str, np.ndarray]:
    """Percentiles of every estimator's position error (numpy.percentile, linear method).

    Parameters
    ----------
    result : dict
        Output of :func:`run`.
    q : float or sequence of float, default (50, 67, 90, 95)
        Percentage levels in [0, 100]; Ke & Wu Table 1 reports 67 and 95.
    discard : bool, default True
        Leave out the first ``result["discard"]`` samples of every run, as the paper does.

    Returns
    -------
    dict
        Estimator name -> array of percentiles (m), one per level (a 0-d array for a scalar q).
    """
    return {
        name: np.percentile(pooled_errors(result, name, discard), q)
        for name in result["estimators"]
    }


def ecdf(errors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Empirical CDF of errors (any shape, flattened).

    Parameters
    ----------
    errors : numpy.ndarray
        Position error norms (m).

    Returns
    -------
    x : numpy.ndarray
        Sorted errors.
    p : numpy.ndarray
        ``p[i] = (i + 1) / n``, the fraction of errors at most ``x[i]``.
    """
    x = np.sort(np.asarray(errors, dtype=float).ravel())
    p = np.arange(1, x.size + 1, dtype=float) / max(x.size, 1)
    return x, p


def rmse(result: dict[str, Any]) -> dict[str, np.ndarray]:
    """RMSE over time across runs (Ke & Wu 2011 Sec. 6.1) of every estimator.

    Parameters
    ----------
    result : dict
        Output of :func:`run`.

    Returns
    -------
    dict
        Estimator name -> array of T values ``sqrt(mean over runs of errors**2)`` (m).
    """
    return {
        name: np.sqrt(np.mean(np.asarray(e["errors"]) ** 2, axis=0))
        for name, e in result["estimators"].items()
    }
