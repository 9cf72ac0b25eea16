"""Plots of Monte Carlo results (needs matplotlib, the ``plots`` extra).

matplotlib is imported inside the functions, so ``import nlosloc.plots`` works without it.

Examples
--------
>>> from nlosloc import montecarlo, plots
>>> res = montecarlo.run("K1", "0LOS/3NLOS", runs=20)  # doctest: +SKIP
>>> ax = plots.error_cdf(res)  # doctest: +SKIP
"""

from __future__ import annotations

from typing import Any

import numpy as np

from nlosloc.montecarlo import ecdf, pooled_errors, rmse

__all__ = ["error_cdf", "error_cdf_from_bench", "rmse_over_time"]


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    _, ax = plt.subplots()
    return ax


def error_cdf(result: dict[str, Any], ax: Any = None, discard: bool = True) -> Any:
    """Empirical CDF of the position error, one line per estimator (Huerta 2009 Figs. 14-15 style).

    Parameters
    ----------
    result : dict
        Output of :func:`nlosloc.montecarlo.run` (or ``nlosloc.sim.run_monte_carlo``).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure's.
    discard : bool, default True
        Leave out the first ``result["discard"]`` samples of every run (as the paper does).

    Returns
    -------
    matplotlib.axes.Axes
        The axes, with x = position error (m), y = P(error <= x).
    """
    ax = _axes(ax)
    for name in result["estimators"]:
        x, p = ecdf(pooled_errors(result, name, discard))
        ax.step(x, p, where="post", label=name)
    ax.set_xlabel("position error (m)")
    ax.set_ylabel("P(error <= x)")
    ax.set_ylim(0.0, 1.0)
    ax.set_title(f"{result.get('scenario', '')} {result.get('case', '')}".strip())
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax


def rmse_over_time(result: dict[str, Any], ax: Any = None) -> Any:
    """RMSE over time across runs, one line per estimator (Ke & Wu 2011 Fig. 2 style).

    Parameters
    ----------
    result : dict
        Output of :func:`nlosloc.montecarlo.run` (or ``nlosloc.sim.run_monte_carlo``).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure's.

    Returns
    -------
    matplotlib.axes.Axes
        The axes, with x = time (s), y = RMSE (m); the discarded transient is shaded.
    """
    ax = _axes(ax)
    dt = float(result["dt"])
    for name, r in rmse(result).items():
        ax.plot(np.arange(r.size) * dt, r, label=name)
    discard = int(result.get("discard", 0))
    if discard > 0:
        ax.axvspan(0.0, discard * dt, color="0.5", alpha=0.15, linewidth=0)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("RMSE (m)")
    ax.set_title(f"{result.get('scenario', '')} {result.get('case', '')}".strip())
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax


def error_cdf_from_bench(
    doc: dict[str, Any], case: str | None = None, ax: Any = None, xmax: float | None = None
) -> Any:
    """Position-error CDFs from the JSON that ``nlosloc-bench run ... --json FILE`` writes.

    Parameters
    ----------
    doc : dict
        The parsed JSON document (``json.load``); its ``results[case]["estimators"][name]["ecdf"]``
        holds the pooled ECDF points ``x`` (m) and ``p``.
    case : str, optional
        Case to draw; default the first case of the document.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure's.
    xmax : float, optional
        Upper limit of the x axis (m); default the largest error drawn.

    Returns
    -------
    matplotlib.axes.Axes
        The axes, with x = position error (m), y = P(error <= x), one step line per estimator.
    """
    ax = _axes(ax)
    results = doc["results"]
    if case is None:
        case = next(iter(results))
    if case not in results:
        raise ValueError(f"case: {case!r} is not in the document; expected one of {list(results)}")
    for name, est in results[case]["estimators"].items():
        x = np.asarray(est["ecdf"]["x"], dtype=float)
        p = np.asarray(est["ecdf"]["p"], dtype=float)
        ax.step(x, p, where="post", label=name)
    if xmax is not None:
        ax.set_xlim(0.0, xmax)
    ax.set_xlabel("position error (m)")
    ax.set_ylabel("P(error <= x)")
    ax.set_ylim(0.0, 1.0)
    scenario = doc.get("config", {}).get("scenario", "")
    runs = doc.get("config", {}).get("runs", "")
    ax.set_title(f"{scenario} {case} ({runs} runs)".strip())
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax
