"""
Scenarios, simulator, Monte Carlo runner and metrics.
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
__all__: list[str] = ['draw', 'ecdf', 'percentiles', 'probability_within', 'rmse_over_time', 'run_monte_carlo', 'scenario_info', 'scenarios']
def draw(name: str, case: str, seed: typing.SupportsInt | typing.SupportsIndex, run: typing.SupportsInt | typing.SupportsIndex, steps: typing.SupportsInt | typing.SupportsIndex | None = None) -> dict:
    """
    One realisation of a scenario case, generated from ``Rng(seed, run)``.
    
    Parameters
    ----------
    name : str
        Scenario name.
    case : str
        Case name (see ``scenario_info(name)["cases"]``).
    seed : int
        Seed (>= 0).
    run : int
        Run index (the generator's stream).
    steps : int, optional
        Number of steps T; default the scenario's. A shorter draw is a prefix of a longer one.
    
    Returns
    -------
    dict
        ``states`` (T x n), ``positions`` (T x D, m), ``y`` (T x m measurements, NaN = missing),
        ``sight`` (T x B int, 0 = LOS), ``quality`` (T x B, NaN when the scenario has none),
        ``initial_mean`` (n), ``initial_cov`` (n x n), and ``scenario``, ``case``, ``seed``, ``run``, ``dt``.
    """
def ecdf(values: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], max_points: typing.SupportsInt | typing.SupportsIndex = 0) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
    """
    Empirical CDF.
    
    Parameters
    ----------
    values : array_like
        Values (flattened).
    max_points : int, default 0
        Keep at most this many points, evenly spaced in rank (0 keeps all).
    
    Returns
    -------
    tuple of numpy.ndarray
        ``(x, p)``: x ascending and ``p[i] = rank(x[i]) / n``.
    """
def percentiles(values: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> numpy.typing.NDArray[numpy.float64]:
    """
    Percentiles by linear interpolation (numpy.percentile's default method).
    
    Parameters
    ----------
    values : array_like
        Values (flattened).
    q : array_like
        Percentage levels in [0, 100].
    
    Returns
    -------
    numpy.ndarray
        One percentile per level; NaN if values is empty or holds a NaN.
    """
def probability_within(values: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], threshold: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    Fraction of values at most ``threshold`` (Ke & Wu 2011 Sec. 6.4).
    
    Parameters
    ----------
    values : array_like
        Values (flattened); NaN counts as above the threshold.
    threshold : float
        Threshold (same unit as values).
    
    Returns
    -------
    float
        The fraction, NaN for an empty input.
    """
def rmse_over_time(errors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    Root mean square error at each step across runs (Ke & Wu 2011 Sec. 6.1).
    
    Parameters
    ----------
    errors : numpy.ndarray
        runs x T position error norms (m).
    
    Returns
    -------
    numpy.ndarray
        T values ``sqrt(mean over runs of errors**2)``.
    """
def run_monte_carlo(name: str, case: str, runs: typing.SupportsInt | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex, estimators: collections.abc.Sequence[str] | None = None, threads: typing.SupportsInt | typing.SupportsIndex = 0, steps: typing.SupportsInt | typing.SupportsIndex | None = None, progress: typing.Any = None) -> dict:
    """
    Monte Carlo run of registered estimators on identical draws.
    
    Every run's draw is generated once and fed to every estimator; the result does not depend on
    ``threads``. The GIL is released while the workers run; Ctrl-C cancels.
    
    Parameters
    ----------
    name : str
        Scenario name.
    case : str
        Case name.
    runs : int
        Number of runs (>= 1).
    seed : int
        Seed; run r draws from ``Rng(seed, r)``.
    estimators : list of str, optional
        Estimator names; default all registered for the scenario.
    threads : int, default 0
        Worker threads; 0 uses every core.
    steps : int, optional
        Steps per run; default the scenario's.
    progress : callable, optional
        ``progress(done, total)``, called on the calling thread (with the GIL) as runs complete.
    
    Returns
    -------
    dict
        ``estimators``: dict name -> {``errors``: runs x T position error norms (m),
        ``time_per_step_ns``: runs, and for estimators that classify sight ``sight_accuracy``:
        (runs, T) fraction of anchors classified correctly, ``sight_anchor_accuracy``: (runs, B)}; and ``scenario``, ``case``, ``runs``, ``steps``, ``seed``,
        ``discard``, ``dt`` (s), ``threads``, ``wall_seconds``.
    
    Raises
    ------
    ValueError
        On an unknown scenario, case or estimator name, or a bad count.
    """
def scenario_info(name: str) -> dict:
    """
    Description of a scenario.
    
    Parameters
    ----------
    name : str
        Scenario name (see :func:`scenarios`).
    
    Returns
    -------
    dict
        ``name``, ``description``, ``choices`` (list of str: values taken where the paper is silent),
        ``cases`` (list of str), ``estimators`` (registered names), ``steps``, ``dt`` (s), ``discard``
        (first samples left out of the statistics), ``state_dim``, ``anchors`` (B x D, m),
        ``paper_source`` and ``paper`` (list of dicts ``estimator``, ``case``, ``metric``, ``value``: the
        published numbers, for every estimator the paper reports).
    
    Raises
    ------
    ValueError
        If the scenario is unknown.
    """
def scenarios() -> list[str]:
    """
    Names of the registered scenarios.
    
    Returns
    -------
    list of str
        Scenario names in registration order, e.g. ``["K1"]``.
    """
