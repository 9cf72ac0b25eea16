"""Monte Carlo helpers around :func:`nlosloc.sim.run_monte_carlo`.

``run`` adds a progress bar (tqdm when installed, else a plain stderr line) and runs the runs on an
executor (processes, or machines through dask.distributed) in chunks that ``merge`` joins;
``percentiles``, ``ecdf`` and ``rmse`` compute the paper statistics of its result with numpy.

Examples
--------
>>> from nlosloc import montecarlo
>>> res = montecarlo.run("K1", "2LOS/1NLOS", runs=10, progress=False)
>>> montecarlo.percentiles(res, (67, 95))["EKF"]  # doctest: +SKIP
array([312.1, 380.4])
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from nlosloc._core import sim as _sim

__all__ = ["ecdf", "merge", "percentiles", "pooled_errors", "rmse", "run"]


def run(
    name: str | _sim.Scenario,
    case: str,
    runs: int = 100,
    seed: int = 1,
    estimators: Sequence[str | tuple[str, Callable[[Any, int], Any]]] | None = None,
    threads: int = 0,
    steps: int | None = None,
    progress: bool | Callable[[int, int], object] = True,
    first_run: int = 0,
    executor: Any = None,
    chunk_runs: int | None = None,
) -> dict[str, Any]:
    """Run a scenario's estimators, registered or written in Python, on identical draws.

    Parameters
    ----------
    name : str or nlosloc.sim.Scenario
        Scenario name (see ``nlosloc.sim.scenarios()``), or a scenario object such as
        ``sim.H2(params)`` (scenarios pickle as their class and parameters).
    case : str
        Case name (see ``nlosloc.sim.scenario_info(name)["cases"]``).
    runs : int, default 100
        Number of runs.
    seed : int, default 1
        Seed; run r draws from ``Rng(seed, r)``.
    estimators : sequence, optional
        Registered estimator names, ``(name, factory)`` pairs of estimators written in Python
        (an object with ``reset(draw, rng)``, ``step(k, y, o) -> position`` and optionally
        ``sight_estimate()``) and ``(name, filter)`` pairs with a filter, tracker or snapshot
        baseline object that runs natively (see :func:`nlosloc.sim.run_monte_carlo`); default
        (None) all registered for the scenario. An empty list raises ValueError.
    threads : int, default 0
        Worker threads (0 = every core) of each run_monte_carlo call. The result does not depend
        on it. With ``executor``, set it to the cores each of its workers may use.
    steps : int, optional
        Steps per run; default the scenario's.
    progress : bool or callable, default True
        True shows a progress bar (tqdm if installed), False shows nothing, a callable is called as
        ``progress(done, total)``.
    first_run : int, default 0
        Index of the first run: runs ``first_run`` .. ``first_run + runs - 1``, each the same as in
        a run from 0 (so separate calls cover one long run; :func:`merge` joins them).
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Runs the runs in chunks of ``chunk_runs`` through ``executor.submit`` (other processes or
        machines) and joins the chunks with :func:`merge`: the result equals the one of a single
        call. The arguments travel by pickle: factories of Python estimators must pickle too
        (module-level classes; dask also pickles lambdas). Options, models, the Kalman filters
        (``Kf``, ``Ekf``, ``Ukf``, ``UkfAugmented``), the ``Iukf``, the ``Rbpf``, the joint
        ``ParticleFilter``, the Ke & Wu trackers (``QpBiasEkf``, ``BiasAugmentedEkf``) and the
        built-in box-QP solvers pickle.
    chunk_runs : int, optional
        Runs per chunk with ``executor``; default ``ceil(runs / 16)``.

    Returns
    -------
    dict
        As :func:`nlosloc.sim.run_monte_carlo`: ``estimators`` maps each name to ``errors``
        (runs x T, m) and ``time_per_step_ns`` (runs); plus ``discard``, ``dt``, ``runs``,
        ``first_run``, ``steps``, ``seed``, ``threads``, ``wall_seconds``, ``scenario``, ``case``,
        ``case_index``.
        With ``executor``, ``wall_seconds`` is the whole call's and ``threads`` the largest of the
        chunks'.
    """
    if isinstance(estimators, (str, bytes)):  # list("EKF") would be the estimators 'E', 'K', 'F'
        raise TypeError(
            "estimators: expected a list of estimator names and (name, factory) pairs, "
            "got a single string"
        )
    est = list(estimators) if estimators is not None else None
    if est == []:  # before any worker starts; as nlosloc.sim.run_monte_carlo
        raise ValueError(
            "estimators: expected at least one estimator, got an empty list "
            "(None: every estimator registered for the scenario)"
        )
    if executor is not None:
        return _run_chunks(
            name, case, runs, seed, est, threads, steps, progress, first_run, executor, chunk_runs
        )
    if chunk_runs is not None:
        raise ValueError("chunk_runs: only with an executor")

    def call(callback: Callable[[int, int], object] | None) -> dict[str, Any]:
        return _sim.run_monte_carlo(
            name, case, runs, seed, est, threads, steps, callback, first_run=first_run
        )

    if callable(progress):
        return call(progress)
    if not progress:
        return call(None)
    bar = _Bar(total=runs, desc=f"{_label(name)} {case}")
    try:
        return call(bar.update)
    finally:
        bar.close()


def _int_arg(value: Any, name: str, lowest: int) -> int:
    """An integer argument (numpy's included, as the C++ runner takes them) >= lowest, as int."""
    integer = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
    if not integer or value < lowest:
        raise ValueError(f"{name}: expected an int >= {lowest}, got {value!r}")
    return int(value)


def _label(name: str | _sim.Scenario) -> str:
    return name if isinstance(name, str) else name.name


def _run_chunk(
    name: str | _sim.Scenario,
    case: str,
    runs: int,
    seed: int,
    estimators: list[Any] | None,
    threads: int,
    steps: int | None,
    first_run: int,
) -> dict[str, Any]:
    """One chunk of an executor's run (module level, so it pickles)."""
    return _sim.run_monte_carlo(
        name, case, runs, seed, estimators, threads, steps, None, first_run=first_run
    )


def _run_chunks(
    name: str | _sim.Scenario,
    case: str,
    runs: int,
    seed: int,
    estimators: list[Any] | None,
    threads: int,
    steps: int | None,
    progress: bool | Callable[[int, int], object],
    first_run: int,
    executor: Any,
    chunk_runs: int | None,
) -> dict[str, Any]:
    if not callable(getattr(executor, "submit", None)):
        raise TypeError(
            "executor: expected an object with submit(fn, *args) returning futures, such as a "
            "concurrent.futures.Executor or a dask.distributed.Client, "
            f"got {type(executor).__name__}"
        )
    runs = _int_arg(runs, "runs", 1)
    first_run = _int_arg(first_run, "first_run", 0)
    if first_run + runs - 1 > 2**64 - 1:  # as sim.run_monte_carlo says it, before any chunk runs
        raise ValueError(
            "first_run: expected first_run + runs - 1 <= 2^64 - 1, got first_run "
            f"{first_run} and runs {runs}"
        )
    chunk_runs = -(-runs // 16) if chunk_runs is None else _int_arg(chunk_runs, "chunk_runs", 1)
    # Checked here, where the error is clear, rather than in every chunk.
    label = _label(name)
    cases = _sim.scenario_info(name)["cases"] if isinstance(name, str) else name.cases
    if case not in cases:
        raise ValueError(
            f"case: unknown case '{case}' of scenario {label}; expected one of: " + ", ".join(cases)
        )
    registered = _sim.scenario_info(label)["estimators"] if label in _sim.scenarios() else []
    for e in estimators or []:
        if isinstance(e, str) and e not in registered:
            raise ValueError(
                f"estimators: unknown estimator '{e}' for scenario {label}; expected one of: "
                + ", ".join(registered)
            )
    t0 = time.perf_counter()
    starts = range(first_run, first_run + runs, chunk_runs)
    sizes = [min(chunk_runs, first_run + runs - start) for start in starts]
    futures = [
        executor.submit(_run_chunk, name, case, n, seed, estimators, threads, steps, start)
        for start, n in zip(starts, sizes)
    ]
    report = progress if callable(progress) else None
    bar = _Bar(total=runs, desc=f"{label} {case}") if progress and report is None else None
    try:
        pending = set(range(len(futures)))
        done = 0
        while pending:
            finished = sorted(i for i in pending if futures[i].done())
            if not finished:
                time.sleep(0.05)
                continue
            for i in finished:
                futures[i].result()  # raises the chunk's exception here
                done += sizes[i]
                pending.discard(i)
            if report is not None:
                report(done, runs)
            if bar is not None:
                bar.update(done, runs)
        results = [f.result() for f in futures]
    except BaseException:
        for f in futures:
            f.cancel()
        raise
    finally:
        if bar is not None:
            bar.close()
    merged = merge(results)
    merged["wall_seconds"] = time.perf_counter() - t0
    return merged


# Keys merge() reads from every result (first_run and case_index may be absent: older results).
_RESULT_KEYS = (
    "scenario",
    "case",
    "seed",
    "steps",
    "discard",
    "dt",
    "runs",
    "threads",
    "wall_seconds",
    "estimators",
)


def merge(results: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Join results of consecutive runs of one Monte Carlo run (``first_run`` chunks).

    Parameters
    ----------
    results : sequence of dict
        Outputs of :func:`run` or :func:`nlosloc.sim.run_monte_carlo` for the same scenario,
        case, seed, steps and estimators (in the same order), whose runs follow each other
        (``first_run`` of each = ``first_run + runs`` of the previous one, in any order given).

    Returns
    -------
    dict
        The result of one call over all their runs: the arrays stacked by run, ``runs`` summed,
        ``first_run`` the smallest, ``threads`` the largest, ``wall_seconds`` summed.

    Raises
    ------
    TypeError
        If an item is not a dict.
    ValueError
        If the list is empty, a result lacks a key of run_monte_carlo's, the results differ in
        anything but their runs, or their runs leave a gap or overlap.
    """
    if len(results) == 0:
        raise ValueError("results: expected at least one result")
    for i, r in enumerate(results):
        if not isinstance(r, dict):
            raise TypeError(
                f"results[{i}]: expected a dict of run_monte_carlo, got {type(r).__name__}"
            )
        missing = [k for k in _RESULT_KEYS if k not in r]
        if missing:
            raise ValueError(f"results[{i}]: expected a dict of run_monte_carlo, missing {missing}")
    ordered = sorted(results, key=lambda r: int(r.get("first_run", 0)))
    first = ordered[0]
    keys = ("scenario", "case", "seed", "steps", "discard", "dt")
    if all("case_index" in r for r in ordered):  # absent from results saved before it was added
        keys += ("case_index",)
    names = list(first["estimators"])
    end = int(first.get("first_run", 0))
    for r in ordered:
        for k in keys:
            if r[k] != first[k]:
                raise ValueError(f"results: {k} differs between chunks ({first[k]!r} and {r[k]!r})")
        if list(r["estimators"]) != names:
            raise ValueError(
                f"results: estimators differ between chunks ({names} and {list(r['estimators'])})"
            )
        start = int(r.get("first_run", 0))
        if start != end:
            raise ValueError(
                f"results: runs from {start} follow runs ending at {end - 1}; expected the runs "
                "to follow each other without a gap or an overlap"
            )
        end = start + int(r["runs"])
    out = {k: first[k] for k in keys}
    out["runs"] = end - int(first.get("first_run", 0))
    out["first_run"] = int(first.get("first_run", 0))
    out["threads"] = max(int(r["threads"]) for r in ordered)
    out["wall_seconds"] = float(sum(r["wall_seconds"] for r in ordered))
    estimators = {}
    for n in names:
        parts = [r["estimators"][n] for r in ordered]
        fields = set(parts[0])
        if any(set(p) != fields for p in parts):
            raise ValueError(f"results: estimator '{n}' has different fields in different chunks")
        estimators[n] = {
            f: (np.concatenate if f == "time_per_step_ns" else np.vstack)([p[f] for p in parts])
            for f in parts[0]
        }
    out["estimators"] = estimators
    return out


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
        The fraction of errors at most ``x[i]`` (tied errors share the largest rank; a NaN, sorted
        last, keeps its own rank ``i + 1``): ``sim.ecdf`` of the flattened errors.
    """
    return _sim.ecdf(np.asarray(errors, dtype=float).ravel())


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
