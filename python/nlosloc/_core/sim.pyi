"""
Scenarios, simulator, Monte Carlo runner and metrics.
"""
from __future__ import annotations
import collections.abc
import nlosloc._core.models
import nlosloc._core.noise
import nlosloc._core.situation
import numpy
import numpy.typing
import typing
__all__: list[str] = ['H1', 'H1Params', 'H2', 'H2Params', 'Scenario', 'draw', 'ecdf', 'percentiles', 'probability_within', 'rmse_over_time', 'run_monte_carlo', 'scenario_info', 'scenarios']
class Scenario:
    """
    A simulation scenario: geometry, measurement stack and a draw() of truth + data.
    """
    def case_index(self, case: str) -> int:
        """
        Index of a case name; ValueError listing the valid names.
        """
    def draw(self, case: str, seed: typing.SupportsInt | typing.SupportsIndex, run: typing.SupportsInt | typing.SupportsIndex, steps: typing.SupportsInt | typing.SupportsIndex | None = None) -> dict:
        """
        One realisation of a case from Rng(seed, run); the same dict as nlosloc.sim.draw().
        """
    @property
    def anchors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, D) anchor positions (m).
        """
    @property
    def cases(self) -> list[str]:
        """
        Case names.
        """
    @property
    def choices(self) -> list[str]:
        """
        Values taken where the paper is silent.
        """
    @property
    def description(self) -> str:
        """
        One line with the paper and section.
        """
    @property
    def discard(self) -> int:
        """
        First samples left out of the statistics.
        """
    @property
    def dt(self) -> float:
        """
        Sampling period (s).
        """
    @property
    def measurements(self) -> nlosloc._core.models.MeasurementStack:
        """
        The models.MeasurementStack that generates the draws' y.
        """
    @property
    def name(self) -> str:
        """
        Short name ("H1").
        """
    @property
    def paper_source(self) -> str:
        """
        Where the published numbers are.
        """
    @property
    def space_dim(self) -> int:
        """
        Space dimension D.
        """
    @property
    def state_dim(self) -> int:
        """
        Size n of the true state.
        """
    @property
    def steps(self) -> int:
        """
        Default number of steps T of a run.
        """
class H1Params:
    """
    Parameters of H1 (Huerta et al. 2009 Sec. VI-A, Tables VII-VIII, plus choices). Checked when an H1 is built from them (ValueError naming the field).
    """
    def __init__(self) -> None:
        ...
    @property
    def aoa_los_var(self) -> float:
        """
        Table VIII: AOA LOS Normal variance (rad^2), > 0.
        """
    @aoa_los_var.setter
    def aoa_los_var(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def aoa_nlos_var(self) -> float:
        """
        Table VIII: AOA NLOS Normal variance (rad^2), > 0.
        """
    @aoa_nlos_var.setter
    def aoa_nlos_var(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def discard(self) -> int:
        """
        Choice: first samples left out, 0 <= discard < steps.
        """
    @discard.setter
    def discard(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def dt(self) -> float:
        """
        Table VII: Delta t (s), > 0.
        """
    @dt.setter
    def dt(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def heading(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Choice: direction of motion, unit vector (2,).
        """
    @heading.setter
    def heading(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
    @property
    def initial_std(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Choice: initial belief std (m, m, m/s, m/s), (4,), > 0.
        """
    @initial_std.setter
    def initial_std(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
    @property
    def mean_los(self) -> float:
        """
        Table VII: E{L_LOS} (m), > 0.
        """
    @mean_los.setter
    def mean_los(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mean_nlos(self) -> float:
        """
        Table VII: E{L_NLOS} (m), > 0.
        """
    @mean_nlos.setter
    def mean_nlos(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_los_a(self) -> float:
        """
        Choice: o | LOS ~ Beta(a, b), a > 0.
        """
    @quality_los_a.setter
    def quality_los_a(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_los_b(self) -> float:
        """
        Choice: o | LOS ~ Beta(a, b), b > 0.
        """
    @quality_los_b.setter
    def quality_los_b(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_nlos_a(self) -> float:
        """
        Choice: o | NLOS ~ Beta(a, b), a > 0.
        """
    @quality_nlos_a.setter
    def quality_nlos_a(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_nlos_b(self) -> float:
        """
        Choice: o | NLOS ~ Beta(a, b), b > 0.
        """
    @quality_nlos_b.setter
    def quality_nlos_b(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rbpf_particles(self) -> int:
        """
        Sec. VI-A: particles of rRBPF-8, >= 1.
        """
    @rbpf_particles.setter
    def rbpf_particles(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def sector_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Choice: broadsides of the three sectors (deg), (3,).
        """
    @sector_deg.setter
    def sector_deg(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
    @property
    def sigma_v2(self) -> float:
        """
        Table VII: filters' sigma_v^2 ((m/s)^2 per s), >= 0.
        """
    @sigma_v2.setter
    def sigma_v2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def speed(self) -> float:
        """
        Table VII: mobile speed (m/s), > 0.
        """
    @speed.setter
    def speed(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def start(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Choice: start (m), (2,).
        """
    @start.setter
    def start(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
    @property
    def steps(self) -> int:
        """
        Table VII: number of steps (200 s), > discard.
        """
    @steps.setter
    def steps(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def toa_los_var(self) -> float:
        """
        Table VIII: TOA LOS Normal variance (m^2), > 0.
        """
    @toa_los_var.setter
    def toa_los_var(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def toa_nlos_var(self) -> float:
        """
        Table VIII: TOA NLOS Rayleigh variance (m^2), > 0.
        """
    @toa_nlos_var.setter
    def toa_nlos_var(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class H1(Scenario):
    """
    Scenario H1 (Huerta et al. 2009 Sec. VI-A): one tri-sector BS, TOA + AOA phase. Built with custom H1Params it runs with run_monte_carlo(scenario, ...) and the estimators registered for H1.
    """
    def __init__(self, params: H1Params = ...) -> None:
        ...
    def serving_sector(self, theta: typing.SupportsFloat | typing.SupportsIndex) -> int:
        """
        Index (0..2) of the sector serving a mobile at bearing theta (rad).
        """
    @property
    def motion(self) -> nlosloc._core.models.ConstantVelocity2:
        """
        Filters' models.ConstantVelocity2 (Huerta eqs. 6-7, random walk sigma_v^2).
        """
    @property
    def params(self) -> H1Params:
        """
        A copy of its H1Params.
        """
    @property
    def quality(self) -> list[nlosloc._core.noise.Distribution]:
        """
        Quality likelihoods per condition [LOS, NLOS] (noise.Distribution).
        """
    @property
    def sight_process(self) -> nlosloc._core.situation.SightProcess:
        """
        The situation.SightProcess of the single anchor (eq. 17).
        """
class H2Params:
    """
    Parameters of H2 (Huerta et al. 2009 Sec. VI-B, Tables IX-X, plus choices). Checked when an H2 is built from them (ValueError naming the field).
    """
    def __init__(self) -> None:
        ...
    @property
    def discard(self) -> int:
        """
        Choice: first samples left out, 0 <= discard < steps.
        """
    @discard.setter
    def discard(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def dt(self) -> float:
        """
        Table IX: Delta t (s), > 0.
        """
    @dt.setter
    def dt(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mean_los(self) -> float:
        """
        Table IX: E{L_LOS} (m), > 0.
        """
    @mean_los.setter
    def mean_los(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mean_nlos(self) -> float:
        """
        Table IX: E{L_NLOS} (m), > 0.
        """
    @mean_nlos.setter
    def mean_nlos(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def pf_particles(self) -> int:
        """
        Sec. VI-B: particles of PF, >= 1.
        """
    @pf_particles.setter
    def pf_particles(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def position0_std(self) -> float:
        """
        Choice: std of the start (m), > 0.
        """
    @position0_std.setter
    def position0_std(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_los_a(self) -> float:
        """
        Choice: o | LOS ~ Beta(a, b), a > 0.
        """
    @quality_los_a.setter
    def quality_los_a(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_los_b(self) -> float:
        """
        Choice: o | LOS ~ Beta(a, b), b > 0.
        """
    @quality_los_b.setter
    def quality_los_b(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_nlos_a(self) -> float:
        """
        Choice: o | NLOS ~ Beta(a, b), a > 0.
        """
    @quality_nlos_a.setter
    def quality_nlos_a(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_nlos_b(self) -> float:
        """
        Choice: o | NLOS ~ Beta(a, b), b > 0.
        """
    @quality_nlos_b.setter
    def quality_nlos_b(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rtoa_los_var(self) -> float:
        """
        Table X: RTOA LOS Normal variance, > 0.
        """
    @rtoa_los_var.setter
    def rtoa_los_var(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rtoa_nlos_var(self) -> float:
        """
        Table X: RTOA NLOS Rayleigh variance, > 0.
        """
    @rtoa_nlos_var.setter
    def rtoa_nlos_var(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def side(self) -> float:
        """
        Sec. VI-B: hexagon side = circumradius (m), > 0.
        """
    @side.setter
    def side(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma_tau2(self) -> float:
        """
        Table IX: drift random walk sigma_tau^2, >= 0.
        """
    @sigma_tau2.setter
    def sigma_tau2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma_v2(self) -> float:
        """
        Table IX: velocity random walk sigma_v^2, >= 0.
        """
    @sigma_v2.setter
    def sigma_v2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def steps(self) -> int:
        """
        Table IX: number of steps (60 s), > discard.
        """
    @steps.setter
    def steps(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def tau0_var(self) -> float:
        """
        Table IX: E{tau_0^2} (lm^2), > 0.
        """
    @tau0_var.setter
    def tau0_var(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tau_dot0_var(self) -> float:
        """
        Table IX: E{tau_dot_0^2} ((lm/s)^2), > 0.
        """
    @tau_dot0_var.setter
    def tau_dot0_var(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def urr_speed(self) -> float:
        """
        Choice: transversal speed (m/s) of URR's switch probabilities, > 0.
        """
    @urr_speed.setter
    def urr_speed(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def velocity0_std(self) -> float:
        """
        Choice: std of the initial velocity, > 0.
        """
    @velocity0_std.setter
    def velocity0_std(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class H2(Scenario):
    """
    Scenario H2 (Huerta et al. 2009 Sec. VI-B): six RTOA anchors on a hexagon, unsynchronised mobile. Built with custom H2Params it runs with run_monte_carlo(scenario, ...) and the estimators registered for H2.
    """
    def __init__(self, params: H2Params = ...) -> None:
        ...
    def prior_variances(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (6,) diagonal of the prior covariance of x_0 = [p, tau, v, tau_dot].
        """
    def urr_nlos_span(self) -> float:
        """
        URR's uniform NLOS span W: the 99% quantile of the NLOS noise.
        """
    def urr_switch_probability(self, condition: typing.SupportsInt | typing.SupportsIndex) -> float:
        """
        URR's per-step probability of leaving `condition` (0 LOS, 1 NLOS), Huerta eq. (15).
        """
    @property
    def motion(self) -> nlosloc._core.models.ConstantVelocityClock2:
        """
        Filters' models.ConstantVelocityClock2 (Huerta eqs. 5-7).
        """
    @property
    def params(self) -> H2Params:
        """
        A copy of its H2Params.
        """
    @property
    def quality(self) -> list[nlosloc._core.noise.Distribution]:
        """
        Quality likelihoods per condition [LOS, NLOS] (noise.Distribution).
        """
    @property
    def sight_process(self) -> nlosloc._core.situation.SightProcess:
        """
        The situation.SightProcess (one eq. 17 chain per anchor).
        """
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
@typing.overload
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
@typing.overload
def run_monte_carlo(scenario: Scenario, case: str, runs: typing.SupportsInt | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex, estimators: collections.abc.Sequence[str] | None = None, threads: typing.SupportsInt | typing.SupportsIndex = 0, steps: typing.SupportsInt | typing.SupportsIndex | None = None, progress: typing.Any = None) -> dict:
    """
    Monte Carlo run on a scenario object, e.g. ``H2(params)`` with custom parameters.
    
    The same as the overload taking a name, with the estimators registered for ``scenario.name``
    (their factories build each estimator from this scenario's models, so custom parameters reach them).
    
    Parameters
    ----------
    scenario : Scenario
        An H1 or H2 (or any Scenario whose name is registered).
    case, runs, seed, estimators, threads, steps, progress
        As in the overload taking a name.
    
    Returns
    -------
    dict
        As in the overload taking a name.
    
    Raises
    ------
    ValueError
        On an unknown case or estimator name, or a bad count.
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
