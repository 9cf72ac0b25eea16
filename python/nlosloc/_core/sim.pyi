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
__all__: list[str] = ['CaseSummary', 'CustomScenario', 'EstimatorSummary', 'H1', 'H1Params', 'H2', 'H2Params', 'K1', 'K1Params', 'K2', 'K2EstimatorStudy', 'K2Params', 'K2Study', 'K3', 'K3Params', 'Scenario', 'backdate', 'default_levels', 'draw', 'ecdf', 'estimator_seed', 'format_choices', 'format_k2_study', 'format_k3_probability', 'format_percentile_table', 'format_table', 'percentile', 'percentiles', 'probability_within', 'rmse_over_time', 'run_k2_study', 'run_monte_carlo', 'scenario', 'scenario_info', 'scenarios', 'summarize']
class Scenario:
    """
    A simulation scenario: geometry, measurement stack and a draw() of truth + data.
    """
    def case_index(self, case: str) -> int:
        """
        Index of a case name; ValueError listing the valid names.
        """
    def draw(self, case: str, seed: int, run: int, steps: typing.SupportsInt | typing.SupportsIndex | None = None) -> dict:
        """
        One realisation of a case from Rng(seed, run); the same dict as nlosloc.sim.draw().
        """
    def paper_value(self, estimator: str, case: str, metric: str) -> float | None:
        """
        The published value of `metric` ("p67", "p95", "time_per_step_us") for an estimator on a case, or None when the paper gives none (an unknown case is a ValueError).
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
    def paper(self) -> list:
        """
        Published numbers: list of dicts estimator, case, metric, value.
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
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        H1Params(**fields): the defaults, with any of the fields (dt, steps, speed, mean_los, mean_nlos, sigma_v2, toa_los_var, toa_nlos_var, aoa_los_var, aoa_nlos_var, discard, rbpf_particles, quality_los_a, quality_los_b, quality_nlos_a, quality_nlos_b, start, heading, sector_deg, initial_std) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def aoa_los_var(self) -> float:
        """
        Table VIII: AOA LOS Normal variance (rad^2), > 0.
        """
    @aoa_los_var.setter
    def aoa_los_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def aoa_nlos_var(self) -> float:
        """
        Table VIII: AOA NLOS Normal variance (rad^2), > 0.
        """
    @aoa_nlos_var.setter
    def aoa_nlos_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def discard(self) -> int:
        """
        Choice: first samples left out, 0 <= discard < steps.
        """
    @discard.setter
    def discard(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def dt(self) -> float:
        """
        Table VII: Delta t (s), > 0.
        """
    @dt.setter
    def dt(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
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
    def mean_los(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mean_nlos(self) -> float:
        """
        Table VII: E{L_NLOS} (m), > 0.
        """
    @mean_nlos.setter
    def mean_nlos(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_los_a(self) -> float:
        """
        Choice: o | LOS ~ Beta(a, b), a > 0.
        """
    @quality_los_a.setter
    def quality_los_a(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_los_b(self) -> float:
        """
        Choice: o | LOS ~ Beta(a, b), b > 0.
        """
    @quality_los_b.setter
    def quality_los_b(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_nlos_a(self) -> float:
        """
        Choice: o | NLOS ~ Beta(a, b), a > 0.
        """
    @quality_nlos_a.setter
    def quality_nlos_a(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_nlos_b(self) -> float:
        """
        Choice: o | NLOS ~ Beta(a, b), b > 0.
        """
    @quality_nlos_b.setter
    def quality_nlos_b(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rbpf_particles(self) -> int:
        """
        Sec. VI-A: particles of rRBPF-8, >= 1.
        """
    @rbpf_particles.setter
    def rbpf_particles(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
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
    def sigma_v2(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def speed(self) -> float:
        """
        Table VII: mobile speed (m/s), > 0.
        """
    @speed.setter
    def speed(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
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
    def steps(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def toa_los_var(self) -> float:
        """
        Table VIII: TOA LOS Normal variance (m^2), > 0.
        """
    @toa_los_var.setter
    def toa_los_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def toa_nlos_var(self) -> float:
        """
        Table VIII: TOA NLOS Rayleigh variance (m^2), > 0.
        """
    @toa_nlos_var.setter
    def toa_nlos_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
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
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        H2Params(**fields): the defaults, with any of the fields (side, dt, steps, sigma_v2, sigma_tau2, tau0_var, tau_dot0_var, mean_los, mean_nlos, rtoa_los_var, rtoa_nlos_var, position0_std, velocity0_std, discard, urr_speed, pf_particles, quality_los_a, quality_los_b, quality_nlos_a, quality_nlos_b) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def discard(self) -> int:
        """
        Choice: first samples left out, 0 <= discard < steps.
        """
    @discard.setter
    def discard(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def dt(self) -> float:
        """
        Table IX: Delta t (s), > 0.
        """
    @dt.setter
    def dt(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mean_los(self) -> float:
        """
        Table IX: E{L_LOS} (m), > 0.
        """
    @mean_los.setter
    def mean_los(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mean_nlos(self) -> float:
        """
        Table IX: E{L_NLOS} (m), > 0.
        """
    @mean_nlos.setter
    def mean_nlos(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def pf_particles(self) -> int:
        """
        Sec. VI-B: particles of PF, >= 1.
        """
    @pf_particles.setter
    def pf_particles(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def position0_std(self) -> float:
        """
        Choice: std of the start (m), > 0.
        """
    @position0_std.setter
    def position0_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_los_a(self) -> float:
        """
        Choice: o | LOS ~ Beta(a, b), a > 0.
        """
    @quality_los_a.setter
    def quality_los_a(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_los_b(self) -> float:
        """
        Choice: o | LOS ~ Beta(a, b), b > 0.
        """
    @quality_los_b.setter
    def quality_los_b(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_nlos_a(self) -> float:
        """
        Choice: o | NLOS ~ Beta(a, b), a > 0.
        """
    @quality_nlos_a.setter
    def quality_nlos_a(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def quality_nlos_b(self) -> float:
        """
        Choice: o | NLOS ~ Beta(a, b), b > 0.
        """
    @quality_nlos_b.setter
    def quality_nlos_b(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rtoa_los_var(self) -> float:
        """
        Table X: RTOA LOS Normal variance, > 0.
        """
    @rtoa_los_var.setter
    def rtoa_los_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rtoa_nlos_var(self) -> float:
        """
        Table X: RTOA NLOS Rayleigh variance, > 0.
        """
    @rtoa_nlos_var.setter
    def rtoa_nlos_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def side(self) -> float:
        """
        Sec. VI-B: hexagon side = circumradius (m), > 0.
        """
    @side.setter
    def side(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma_tau2(self) -> float:
        """
        Table IX: drift random walk sigma_tau^2, >= 0.
        """
    @sigma_tau2.setter
    def sigma_tau2(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma_v2(self) -> float:
        """
        Table IX: velocity random walk sigma_v^2, >= 0.
        """
    @sigma_v2.setter
    def sigma_v2(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def steps(self) -> int:
        """
        Table IX: number of steps (60 s), > discard.
        """
    @steps.setter
    def steps(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def tau0_var(self) -> float:
        """
        Table IX: E{tau_0^2} (lm^2), > 0.
        """
    @tau0_var.setter
    def tau0_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tau_dot0_var(self) -> float:
        """
        Table IX: E{tau_dot_0^2} ((lm/s)^2), > 0.
        """
    @tau_dot0_var.setter
    def tau_dot0_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def urr_speed(self) -> float:
        """
        Choice: transversal speed (m/s) of URR's switch probabilities, > 0.
        """
    @urr_speed.setter
    def urr_speed(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def velocity0_std(self) -> float:
        """
        Choice: std of the initial velocity, > 0.
        """
    @velocity0_std.setter
    def velocity0_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
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
class K1Params:
    """
    Parameters of K1 (Ke & Wu 2011 Secs. 6 and 6.1, plus choices). Checked when a K1 (or a K2 through K2Params.base) is built from them (ValueError naming the field).
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        K1Params(**fields): the defaults, with any of the fields (sigma_los, nlos_mean, nlos_std, nlos_nonnegative, anchors, accel_var, steps, dt, discard, gamma, iterated_bias_prior_std, iterated_bias_walk_std, iterated_iterations, start, velocity, initial_std) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def accel_var(self) -> float:
        """
        Sec. 6: sigma_x^2 = sigma_y^2 of eq. (16) ((m/s^2)^2), >= 0.
        """
    @accel_var.setter
    def accel_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def anchors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Sec. 6: the three fixed nodes (m), (3, 2).
        """
    @anchors.setter
    def anchors(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> None:
        ...
    @property
    def discard(self) -> int:
        """
        First samples left out of the statistics, 0 <= discard < steps.
        """
    @discard.setter
    def discard(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def dt(self) -> float:
        """
        Sec. 6: Delta t (s), > 0.
        """
    @dt.setter
    def dt(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def gamma(self) -> float:
        """
        Sec. 5: scaling factor of the NLOS test, eq. (32), finite >= 1.
        """
    @gamma.setter
    def gamma(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
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
    def iterated_bias_prior_std(self) -> float:
        """
        Choice: iterated NLOS EKF, prior std of each bias (m), > 0.
        """
    @iterated_bias_prior_std.setter
    def iterated_bias_prior_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def iterated_bias_walk_std(self) -> float:
        """
        Choice: iterated NLOS EKF, bias random walk (m/step), >= 0.
        """
    @iterated_bias_walk_std.setter
    def iterated_bias_walk_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def iterated_iterations(self) -> int:
        """
        Choice: iterated NLOS EKF, iterations of the update, >= 1.
        """
    @iterated_iterations.setter
    def iterated_iterations(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def nlos_mean(self) -> float:
        """
        Sec. 6.1: NLOS error b_i ~ N(mean, std^2) (m), > 0.
        """
    @nlos_mean.setter
    def nlos_mean(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def nlos_nonnegative(self) -> bool:
        """
        Choice: b_i = max(0, draw) (Sec. 2, eq. 1: b_i(k) >= 0); False keeps the normal draw.
        """
    @nlos_nonnegative.setter
    def nlos_nonnegative(self, arg1: bool) -> None:
        ...
    @property
    def nlos_std(self) -> float:
        """
        Sec. 6.1: NLOS error std (m), > 0.
        """
    @nlos_std.setter
    def nlos_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma_los(self) -> float:
        """
        Sec. 6: TOA noise n_i ~ N(0, sigma_los^2) (m), > 0.
        """
    @sigma_los.setter
    def sigma_los(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def start(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Start position (m), (2,).
        """
    @start.setter
    def start(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
    @property
    def steps(self) -> int:
        """
        Sec. 6: L, samples per run, > discard.
        """
    @steps.setter
    def steps(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def velocity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Initial velocity (m/s), (2,).
        """
    @velocity.setter
    def velocity(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
class K1(Scenario):
    """
    Scenario K1 (Ke & Wu 2011 Sec. 6.1): three TOA nodes, 0..3 of them NLOS for the whole run. Built with custom K1Params it runs with run_monte_carlo(scenario, ...) and the estimators registered for K1.
    """
    @staticmethod
    def is_nlos(case_index: typing.SupportsInt | typing.SupportsIndex, anchor: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        True when node `anchor` is NLOS in case `case_index` (choice: the last nlos_count nodes).
        """
    @staticmethod
    def nlos_count(case_index: typing.SupportsInt | typing.SupportsIndex) -> int:
        """
        Number of NLOS nodes of case `case_index` (cases hold 0..3 NLOS nodes).
        """
    def __init__(self, params: K1Params = ...) -> None:
        ...
    @property
    def motion(self) -> nlosloc._core.models.ConstantVelocity2:
        """
        Motion model of the truth and of the filters (Ke & Wu eq. 16).
        """
    @property
    def params(self) -> K1Params:
        """
        A copy of its K1Params.
        """
class K2Params:
    """
    Parameters of K2 (Ke & Wu 2011 Sec. 6.2): K1's in `base` plus the switching period. Checked when a K2 is built from them (ValueError naming the field).
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        K2Params(**fields): the defaults, with any of the fields (base, period, start_nlos) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def base(self) -> K1Params:
        """
        K1Params: geometry, noise, motion, L, dt, discard, estimator choices (edited in place).
        """
    @base.setter
    def base(self, arg1: K1Params) -> None:
        ...
    @property
    def period(self) -> int:
        """
        Sec. 6.2: samples between LOS/NLOS switches, >= 1.
        """
    @period.setter
    def period(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def start_nlos(self) -> bool:
        """
        Choice: the first block is NLOS.
        """
    @start_nlos.setter
    def start_nlos(self, arg1: bool) -> None:
        ...
class K2(Scenario):
    """
    Scenario K2 (Ke & Wu 2011 Sec. 6.2): K1's nodes and noise, every node switching between NLOS and LOS every `period` samples. Built with custom K2Params it runs with run_monte_carlo(scenario, ...).
    """
    def __init__(self, params: K2Params = ...) -> None:
        ...
    def nlos_at(self, k: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        True when the nodes are NLOS at sample k.
        """
    @property
    def motion(self) -> nlosloc._core.models.ConstantVelocity2:
        """
        Motion model of the truth and of the filters (Ke & Wu eq. 16).
        """
    @property
    def params(self) -> K2Params:
        """
        A copy of its K2Params.
        """
class K3Params:
    """
    Parameters of K3 (Ke & Wu 2011 Sec. 6.4, plus choices). Checked when a K3 is built from them (ValueError naming the field).
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        K3Params(**fields): the defaults, with any of the fields (sigma_rel, nlos_rel, threshold, good, bad, accel_var, steps, dt, discard, gamma, iterated_bias_prior_std, iterated_bias_walk_std, iterated_iterations, start, velocity, initial_std) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def accel_var(self) -> float:
        """
        Sec. 6: sigma_x^2 = sigma_y^2 of eq. (16) ((m/s^2)^2), >= 0.
        """
    @accel_var.setter
    def accel_var(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def bad(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Sec. 6.4: bad geometry, four nodes (m), (4, 2).
        """
    @bad.setter
    def bad(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> None:
        ...
    @property
    def discard(self) -> int:
        """
        First samples left out of the statistics, 0 <= discard < steps.
        """
    @discard.setter
    def discard(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def dt(self) -> float:
        """
        Sec. 6: Delta t (s), > 0.
        """
    @dt.setter
    def dt(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def gamma(self) -> float:
        """
        Sec. 5: scaling factor of the NLOS test, eq. (32), finite >= 1.
        """
    @gamma.setter
    def gamma(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def good(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Sec. 6.4: good geometry, four nodes (m), (4, 2).
        """
    @good.setter
    def good(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> None:
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
    def iterated_bias_prior_std(self) -> float:
        """
        Choice: iterated NLOS EKF, prior std of each bias (m), > 0.
        """
    @iterated_bias_prior_std.setter
    def iterated_bias_prior_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def iterated_bias_walk_std(self) -> float:
        """
        Choice: iterated NLOS EKF, bias random walk (m/step), >= 0.
        """
    @iterated_bias_walk_std.setter
    def iterated_bias_walk_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def iterated_iterations(self) -> int:
        """
        Choice: iterated NLOS EKF, iterations of the update, >= 1.
        """
    @iterated_iterations.setter
    def iterated_iterations(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def nlos_rel(self) -> float:
        """
        Sec. 6.4: NLOS error exponential with mean nlos_rel d_i, > 0.
        """
    @nlos_rel.setter
    def nlos_rel(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma_rel(self) -> float:
        """
        Sec. 6.4: sigma_i = sigma_rel d_i, > 0.
        """
    @sigma_rel.setter
    def sigma_rel(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def start(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Start position (m), (2,).
        """
    @start.setter
    def start(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
    @property
    def steps(self) -> int:
        """
        Sec. 6: L, samples per run, > discard.
        """
    @steps.setter
    def steps(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def threshold(self) -> float:
        """
        Sec. 6.4: error threshold (m) of P(error <= t), > 0: the bench's line, and format_k3_probability(result, threshold).
        """
    @threshold.setter
    def threshold(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def velocity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Initial velocity (m/s), (2,).
        """
    @velocity.setter
    def velocity(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
class K3(Scenario):
    """
    Scenario K3 (Ke & Wu 2011 Sec. 6.4): four TOA nodes in a good or a bad geometry, 1..4 of them NLOS, noise relative to distance. Built with custom K3Params it runs with run_monte_carlo(scenario, ...).
    """
    @staticmethod
    def bad_geometry(case_index: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        True for the bad-geometry cases (indices 4..7).
        """
    @staticmethod
    def is_nlos(case_index: typing.SupportsInt | typing.SupportsIndex, anchor: typing.SupportsInt | typing.SupportsIndex) -> bool:
        """
        True when node `anchor` is NLOS in case `case_index` (the last nlos_count nodes).
        """
    @staticmethod
    def nlos_count(case_index: typing.SupportsInt | typing.SupportsIndex) -> int:
        """
        Number of NLOS nodes of case `case_index` (1..4).
        """
    def __init__(self, params: K3Params = ...) -> None:
        ...
    def anchors_of(self, case_index: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (4, 2) anchors of case `case_index` (anchors is the good geometry).
        """
    @property
    def motion(self) -> nlosloc._core.models.ConstantVelocity2:
        """
        Motion model of the truth and of the filters (Ke & Wu eq. 16).
        """
    @property
    def params(self) -> K3Params:
        """
        A copy of its K3Params.
        """
class K2EstimatorStudy:
    """
    One estimator's averages in the K2 study.
    """
    @property
    def identification(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"] | None:
        """
        (T,) fraction of (run, node) pairs whose sight was identified (Fig. 5); None for an estimator that does not classify sight.
        """
    @property
    def name(self) -> str:
        ...
    @property
    def position_error(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (T,) mean over runs of ||p^_k - p_k|| (m).
        """
    @property
    def range_error(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (T, B) mean over runs of | ||p^_k - a_i|| - d_i(k) | (m): Ke & Wu Fig. 3.
        """
class K2Study:
    """
    The K2 study: Ke & Wu Figs. 3-5 as numbers (means over runs).
    """
    @property
    def discard(self) -> int:
        ...
    @property
    def estimators(self) -> list[K2EstimatorStudy]:
        """
        One K2EstimatorStudy per estimator, in order.
        """
    @property
    def first_run(self) -> int:
        """
        Index of the first run averaged.
        """
    @property
    def nlos(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        (T,) 1 where the nodes are NLOS.
        """
    @property
    def period(self) -> int:
        ...
    @property
    def runs(self) -> int:
        ...
    @property
    def steps(self) -> int:
        ...
class EstimatorSummary:
    """
    Summary of one estimator on one case.
    """
    def __repr__(self) -> str:
        ...
    def at(self, level: typing.SupportsFloat | typing.SupportsIndex) -> float:
        """
        Percentile at `level` (one of levels); NaN if it was not computed.
        """
    @property
    def levels(self) -> list[float]:
        """
        Percentile levels (%).
        """
    @property
    def name(self) -> str:
        ...
    @property
    def paper_p67(self) -> float | None:
        """
        Published 67% error (m), or None.
        """
    @property
    def paper_p95(self) -> float | None:
        """
        Published 95% error (m), or None.
        """
    @property
    def paper_time_per_step_us(self) -> float | None:
        """
        Published time per step (us), or None.
        """
    @property
    def percentiles(self) -> list[float]:
        """
        Position error (m) at each level, pooled over runs and steps k >= discard.
        """
    @property
    def sight_accuracy(self) -> float | None:
        """
        Fraction of (anchor, step k >= discard) pairs classified correctly; None for an estimator that does not classify sight.
        """
    @property
    def time_per_step_ns(self) -> float:
        """
        Mean over runs of the time per step (ns).
        """
class CaseSummary:
    """
    Summary of one case: one EstimatorSummary per estimator.
    """
    def __repr__(self) -> str:
        ...
    @property
    def case(self) -> str:
        ...
    @property
    def discard(self) -> int:
        ...
    @property
    def estimators(self) -> list[EstimatorSummary]:
        """
        In the result's order.
        """
    @property
    def first_run(self) -> int:
        """
        Index of the first run summarised.
        """
    @property
    def runs(self) -> int:
        ...
    @property
    def scenario(self) -> str:
        ...
    @property
    def steps(self) -> int:
        ...
    @property
    def wall_seconds(self) -> float:
        ...
class CustomScenario(Scenario):
    """
    A scenario defined in Python: your own simulation, or a recording replayed.
    
    It runs wherever a Scenario does (``draw``, ``run_monte_carlo(scenario, ...)``,
    ``nlosloc.montecarlo.run``, ``summarize`` and the tables) with estimators written in Python and
    filters of :mod:`nlosloc.filters` (no estimator is registered for it). ``generate`` is called from
    the runner's worker threads, with the GIL; it must not depend on anything but its arguments if the
    result is to be the same for any number of threads. Scenario objects of this class do not pickle.
    """
    def __init__(self, name: str, measurements: nlosloc._core.models.MeasurementStack, cases: collections.abc.Sequence[str], steps: typing.SupportsInt | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, generate: typing.Any, discard: typing.SupportsInt | typing.SupportsIndex = 0, description: str = '', choices: collections.abc.Sequence[str] = []) -> None:
        """
        Parameters
        ----------
        name : str
            Scenario name (not one of the built-in ones).
        measurements : nlosloc.models.MeasurementStack
            The stack that generates ``y`` (its rows, anchors, conditions; its layout's state size is the
            true state's).
        cases : list of str
            Case names; ``generate`` receives the index of one.
        steps : int
            Default number of steps T of a run (>= 1).
        dt : float
            Sampling period (s), > 0.
        generate : callable
            ``generate(case_index, steps, rng)`` with ``rng`` a ``core.Rng(seed, run)`` (a copy): returns a
            dict of ``states`` (T, n), ``positions`` (T, D), ``y`` (T, m; NaN = missing), ``sight``
            (T, B) integers in [0, N_z), optionally ``quality`` (T, B; NaN when absent), and
            ``initial_mean`` (n,), ``initial_cov`` (n, n) (the belief every estimator starts from).
            Checked on every call (ValueError naming the key).
        discard : int, default 0
            First samples of every run left out of the statistics (< steps).
        description : str, optional
        choices : list of str, optional
            Values you chose, printed with the tables.
        """
    @property
    def generate(self) -> typing.Any:
        """
        The generate callable.
        """
def backdate(motion: typing.Any, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
    """
    The belief (mean, cov) one prediction earlier whose prediction is the given one exactly: F^-1 m, F^-1 (P - Q) F^-T; the given belief itself when P - Q is not positive definite. A filter that predicts before its first update, started from it, sees the draw's initial belief at t_0.
    """
def default_levels() -> list[float]:
    """
    Percentile levels reported by default: [50, 67, 90, 95].
    """
def draw(name: str, case: str, seed: int, run: int, steps: typing.SupportsInt | typing.SupportsIndex | None = None) -> dict:
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
        ``initial_mean`` (n), ``initial_cov`` (n x n), and ``scenario``, ``case``, ``case_index`` (its
        index in ``scenario_info(name)["cases"]``), ``seed``, ``run``, ``dt``.
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
def estimator_seed(seed: int, name: str) -> int:
    """
    Seed of estimator `name`'s generator in a Monte Carlo run with `seed`: run r uses Rng(estimator_seed(seed, name), r), the same whatever other estimators run beside it.
    """
@typing.overload
def format_choices(scenario: Scenario) -> str:
    """
    The scenario header: name, description, the numbered choices made where the paper is silent, and where the published numbers are.
    """
@typing.overload
def format_choices(scenario: str) -> str:
    """
    The same, for a registered scenario name.
    """
def format_k2_study(study: K2Study) -> str:
    """
    The K2 study as text (what nlosloc-bench prints): per estimator, position and ranging errors in NLOS and LOS blocks, identification overall, per sight, near the switches and elsewhere.
    """
def format_k3_probability(result: dict, threshold: typing.SupportsFloat | typing.SupportsIndex = 5.0) -> str:
    """
    One line per estimator: P(position error <= threshold) pooled over runs and steps k >= discard (Ke & Wu Sec. 6.4, Figs. 6-7), from a run_monte_carlo result.
    """
def format_percentile_table(summary: CaseSummary) -> str:
    """
    The case table without paper columns: 50 / 67 / 90 / 95% errors, time per step, sight accuracy.
    """
def format_table(summary: CaseSummary) -> str:
    """
    The case table nlosloc-bench prints: ours and the paper's 67% / 95% errors, their ratios, time per step and sight accuracy; format_percentile_table's when the paper publishes no number for the case.
    """
def percentile(values: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], q: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    The q-th percentile (q in [0, 100]) of `values` (flattened), numpy.percentile's default definition; NaN if values is empty or holds a NaN.
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
def rmse_over_time(errors: numpy.ndarray) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
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
def run_k2_study(runs: typing.SupportsInt | typing.SupportsIndex, seed: int, steps: typing.SupportsInt | typing.SupportsIndex | None = None, estimators: collections.abc.Sequence | None = None, *, first_run: int = 0) -> K2Study:
    """
    The K2 study of Ke & Wu Sec. 6.2 (Figs. 3-5): every estimator registered for K2 (or
    ``estimators``) on the draws ``Rng(seed, r)``, r = ``first_run`` .. ``first_run + runs - 1``, of the
    registered K2, one thread, the same draws as :func:`run_monte_carlo`; position error, ranging error
    and sight identification averaged over runs.
    
    Parameters
    ----------
    runs : int
        Number of runs (>= 1).
    seed : int
        Seed (>= 0).
    steps : int, optional
        Steps per run (>= 1); default the scenario's.
    estimators : list, optional
        Registered estimator names and ``(name, factory)`` pairs of estimators written in Python, as in
        :func:`run_monte_carlo`; default all registered for K2.
    first_run : int, default 0
        Index of the first run (keyword only), as in :func:`run_monte_carlo`.
    
    Returns
    -------
    K2Study
    
    Raises
    ------
    ValueError
        On a bad count, a negative seed or first_run, first_run + runs - 1 beyond 2^64 - 1, an unknown
        estimator or a name given twice.
    TypeError
        On a malformed entry of ``estimators`` (see :func:`run_monte_carlo`).
    """
@typing.overload
def run_k2_study(scenario: K2, runs: typing.SupportsInt | typing.SupportsIndex, seed: int, steps: typing.SupportsInt | typing.SupportsIndex | None = None, estimators: collections.abc.Sequence | None = None, *, first_run: int = 0) -> K2Study:
    """
    The K2 study of a K2 built with custom parameters, e.g. ``K2(p)`` with another period.
    
    The same as the overload without a scenario, on this scenario's draws; registered estimators are
    built from its models, Python estimators' factories get it.
    
    Parameters
    ----------
    scenario : K2
        The scenario.
    runs, seed, steps, estimators, first_run
        As in the overload without a scenario.
    
    Returns
    -------
    K2Study
    
    Raises
    ------
    ValueError, TypeError
        As in the overload without a scenario.
    """
@typing.overload
def run_monte_carlo(name: str, case: str, runs: typing.SupportsInt | typing.SupportsIndex, seed: int, estimators: collections.abc.Sequence | None = None, threads: typing.SupportsInt | typing.SupportsIndex = 0, steps: typing.SupportsInt | typing.SupportsIndex | None = None, progress: typing.Any = None, first_run: int = 0) -> dict:
    """
    Monte Carlo run of estimators, registered or written in Python, on identical draws.
    
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
    estimators : list, optional
        Default (None): every estimator registered for the scenario; an empty list is refused
        (ValueError). Each entry is a registered name (str) or
        a pair ``(name, factory)`` of an estimator written in Python: ``factory(scenario, case_index)``
        (called once per worker thread) returns an object with ``reset(draw, rng)`` (at the start of
        each run: the draw as :func:`draw` returns it, and the estimator's own ``core.Rng``,
        ``Rng(estimator_seed(seed, name), run)``) and ``step(k, y, o)`` (step k's measurements and
        quality statistics, NaN = missing; returns the D position coordinates), and optionally
        ``sight_estimate()`` (after each step: B integer conditions, 0 = LOS; then its result has
        ``sight_accuracy``). Python estimators hold the GIL while they run, so they run one at a
        time beside the C++ ones; their ``time_per_step_ns`` includes the call overhead. An entry
        may also be ``(name, filter)`` with a filter object built for the scenario's model (its
        state size, measurement rows, anchors and dt are checked), which runs natively, without the
        GIL, as the registered estimators do: an ``Ekf``, ``Ukf`` or ``UkfAugmented`` of
        :mod:`nlosloc.filters` (a copy per worker from the draw's initial belief, updated at step 0;
        ``(name, filter, sight)`` with ``sight`` ``"assume_los"``, the default, or ``"oracle"``,
        the draw's true sight: a bound, not an estimator); an ``Iukf``, ``Rbpf`` or
        ``ParticleFilter`` of :mod:`nlosloc.rbpf` (a new filter with the given one's models and
        options per worker; a ParticleFilter's ``options.seed`` is replaced at every run by a draw
        from the estimator's own stream); a ``QpBiasEkf`` or ``BiasAugmentedEkf`` of
        :mod:`nlosloc.mitigation`; ``MleLos``, ``Chen``, ``Cong`` or ``Urruela`` of
        :mod:`nlosloc.snapshot`. Each starts every run as the registered estimator of its kind
        does (``sim/h1.hpp``, ``sim/k1.hpp``), so the same set-up gives the same numbers. The object
        given is not run or changed. A factory may return such an object too (then it runs
        natively, and ``(name, factory, sight)`` takes a sight policy for the Gaussian filters): a
        module-level factory pickles where the particle filters and the trackers do not (the
        Kalman filters and the Iukf pickle too).
    threads : int, default 0
        Worker threads; 0 uses every core.
    steps : int, optional
        Steps per run; default the scenario's.
    progress : callable, optional
        ``progress(done, total)``, called on the calling thread (with the GIL) as runs complete.
    first_run : int, default 0
        Index of the first run: the runs are ``first_run`` .. ``first_run + runs - 1``, each the same
        as in a run from 0 (row r of the result is run ``first_run + r``), so chunks run apart join
        into one result (``nlosloc.montecarlo.merge``).
    
    Returns
    -------
    dict
        ``estimators``: dict name -> {``errors``: runs x T position error norms (m),
        ``time_per_step_ns``: runs, and for estimators that classify sight ``sight_accuracy``:
        (runs, T) fraction of anchors classified correctly, ``sight_anchor_accuracy``: (runs, B)};
        and ``scenario``, ``case``, ``case_index`` (its index in ``scenario_info(name)["cases"]``),
        ``runs``, ``first_run``, ``steps``, ``seed``, ``discard``, ``dt`` (s), ``threads``,
        ``wall_seconds``.
    
    Raises
    ------
    ValueError
        On an unknown scenario, case or estimator name, a name given twice, a bad count, or a Python
        estimator's step() or sight_estimate() result of the wrong size.
    TypeError
        On an entry of ``estimators`` that is neither a name, a (name, callable) pair nor a
        (name, filter[, sight]) tuple, a sight policy with an object other than a Gaussian filter, or
        a factory result without ``reset`` and ``step``. An exception raised inside a Python estimator stops the
        run and is raised here.
    """
@typing.overload
def run_monte_carlo(scenario: Scenario, case: str, runs: typing.SupportsInt | typing.SupportsIndex, seed: int, estimators: collections.abc.Sequence | None = None, threads: typing.SupportsInt | typing.SupportsIndex = 0, steps: typing.SupportsInt | typing.SupportsIndex | None = None, progress: typing.Any = None, first_run: int = 0) -> dict:
    """
    Monte Carlo run on a scenario object, e.g. ``H2(params)`` with custom parameters.
    
    The same as the overload taking a name, with the estimators registered for ``scenario.name``
    (their factories build each estimator from this scenario's models, so custom parameters reach them);
    Python estimators' factories get this object.
    
    Parameters
    ----------
    scenario : Scenario
        An H1 or H2 (or any Scenario whose name is registered).
    case, runs, seed, estimators, threads, steps, progress, first_run
        As in the overload taking a name.
    
    Returns
    -------
    dict
        As in the overload taking a name.
    
    Raises
    ------
    ValueError, TypeError
        As in the overload taking a name.
    """
def scenario(name: str) -> Scenario:
    """
    The registered scenario object (C++ ``registry().scenario_ptr(name)``).
    
    Parameters
    ----------
    name : str
        Scenario name (see :func:`scenarios`).
    
    Returns
    -------
    Scenario
        The object itself, of its own class (``H1``, ``H2``, ``K1``, ...): its geometry, measurement
        stack, published numbers and ``draw``; ``run_monte_carlo(scenario, ...)`` takes it.
    
    Raises
    ------
    ValueError
        If the scenario is unknown.
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
@typing.overload
def summarize(scenario: Scenario, result: dict, levels: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] | None = None) -> CaseSummary:
    """
    Percentiles of the position error pooled over runs and steps
    k >= discard, the mean time per step and the paper's published values, per estimator (what
    nlosloc-bench tabulates).
    
    Parameters
    ----------
    scenario : Scenario or str
        The scenario the result was run on (an object, e.g. ``H2(params)``, or a registered name).
    result : dict
        The dict returned by :func:`run_monte_carlo`.
    levels : list of float, optional
        Percentage levels in [0, 100]; default :func:`default_levels` (50, 67, 90, 95).
    
    Returns
    -------
    CaseSummary
    
    Raises
    ------
    ValueError
        If ``result`` is not a run of ``scenario``, misses a key, or an array has the wrong shape.
    """
@typing.overload
def summarize(scenario: str, result: dict, levels: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] | None = None) -> CaseSummary:
    """
    Percentiles of the position error pooled over runs and steps
    k >= discard, the mean time per step and the paper's published values, per estimator (what
    nlosloc-bench tabulates).
    
    Parameters
    ----------
    scenario : Scenario or str
        The scenario the result was run on (an object, e.g. ``H2(params)``, or a registered name).
    result : dict
        The dict returned by :func:`run_monte_carlo`.
    levels : list of float, optional
        Percentage levels in [0, 100]; default :func:`default_levels` (50, 67, 90, 95).
    
    Returns
    -------
    CaseSummary
    
    Raises
    ------
    ValueError
        If ``result`` is not a run of ``scenario``, misses a key, or an array has the wrong shape.
    """
