"""
Rao-Blackwellized particle filters with merge/prune, joint PF.
"""
from __future__ import annotations
import collections.abc
import nlosloc._core.core
import nlosloc._core.filters
import nlosloc._core.models
import nlosloc._core.situation
import numpy
import numpy.typing
import typing
__all__: list[str] = ['Iukf', 'ParticleFilter', 'PfOptions', 'PfResampling', 'PfSnapshot', 'PfStepInfo', 'Rbpf', 'RbpfOptions', 'RbpfSnapshot', 'RbpfStepInfo', 'RbpfVariant', 'decode_situation', 'default_merge_threshold', 'encode_situation', 'enumerate_best', 'enumerate_offspring', 'merge_greedy', 'pf_simd_lanes', 'select_top', 'situation_count', 'systematic_resample']
class RbpfVariant:
    """
    Order of the RBPF iteration.
    
    Members:
    
      Classical : Table IV: a UKF for every child
    
      Reordered : Table V: merge/select first, M UKFs
    """
    Classical: typing.ClassVar[RbpfVariant]
    Reordered: typing.ClassVar[RbpfVariant]
    __members__: typing.ClassVar[dict[str, RbpfVariant]]
    @typing.overload
    def __eq__(self, other: RbpfVariant) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: RbpfVariant) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class PfResampling:
    """
    Selection step of the joint PF.
    
    Members:
    
      Systematic : systematic resampling when ESS < threshold M
    
      MergeSelect : bucketed merge (eqs. 29-30) then systematic resampling
    """
    MergeSelect: typing.ClassVar[PfResampling]
    Systematic: typing.ClassVar[PfResampling]
    __members__: typing.ClassVar[dict[str, PfResampling]]
    @typing.overload
    def __eq__(self, other: PfResampling) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: PfResampling) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class RbpfOptions:
    """
    Settings of Rbpf.
    """
    merge: bool
    scheme: nlosloc._core.core.SigmaScheme
    variant: RbpfVariant
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, variant: RbpfVariant = RbpfVariant.Reordered, num_particles: typing.SupportsInt | typing.SupportsIndex = 16, max_offspring: int = 4096, merge: bool = True, merge_threshold: typing.SupportsFloat | typing.SupportsIndex = -1.0, threads: typing.SupportsInt | typing.SupportsIndex = 1, scheme: nlosloc._core.core.SigmaScheme = ..., noise_form: nlosloc._core.filters.NoiseForm = nlosloc._core.filters.NoiseForm.Additive) -> None:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def max_offspring(self) -> int:
        """
        Children per particle; above N_z^B the best ones by prior x quality (bounded).
        """
    @max_offspring.setter
    def max_offspring(self, arg1: int) -> None:
        ...
    @property
    def merge_threshold(self) -> float:
        """
        d_min; negative: eq. (31).
        """
    @merge_threshold.setter
    def merge_threshold(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def noise_form(self) -> nlosloc._core.filters.NoiseForm:
        """
        UKF noise: Additive moments (default, one sigma set per parent) or Augmented (Table III's noise sigma set, one sigma set per child).
        """
    @noise_form.setter
    def noise_form(self, arg1: nlosloc._core.filters.NoiseForm) -> None:
        ...
    @property
    def num_particles(self) -> int:
        """
        M, particles propagated (>= 1).
        """
    @num_particles.setter
    def num_particles(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def threads(self) -> int:
        ...
    @threads.setter
    def threads(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class RbpfSnapshot:
    """
    What an Rbpf carries from one step to the next (Rbpf.save / Rbpf.restore): a checkpoint, and what pickling an Rbpf stores. Checked by Rbpf.restore.
    """
    def __init__(self, situations: typing.Annotated[numpy.typing.ArrayLike, numpy.int32, "[m, n]"], means: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], covs: collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]], log_weights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], situation_probabilities: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], estimate: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], covariance: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], time: typing.SupportsFloat | typing.SupportsIndex, step: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        situations (P, B) condition indices, means (P, n), covs: P arrays (n, n) (or one (P, n, n)), log_weights (P,) normalised, situation_probabilities (B, N_z), estimate (n,), covariance (n, n), time (s), step (steps since the reset; 0: the next step draws from the initial sight).
        """
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Eq. (27), moment matched.
        """
    @property
    def covs(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        P covariances (n, n) (eq. 26).
        """
    @property
    def estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Eq. (28).
        """
    @property
    def log_weights(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (P,) normalised log weights.
        """
    @property
    def means(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (P, n) kinetic means (eq. 26).
        """
    @property
    def situation_probabilities(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z).
        """
    @property
    def situations(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, n]"]:
        """
        (P, B) condition indices (0 = LOS).
        """
    @property
    def step(self) -> int:
        ...
    @property
    def time(self) -> float:
        ...
class RbpfStepInfo:
    """
    What one RBPF step reports.
    """
    def __repr__(self) -> str:
        ...
    @property
    def failures(self) -> int:
        ...
    @property
    def log_likelihood(self) -> float:
        ...
    @property
    def merge_threshold(self) -> float:
        ...
    @property
    def merged(self) -> int:
        ...
    @property
    def offspring(self) -> int:
        ...
    @property
    def status(self) -> nlosloc._core.core.CholeskyStatus:
        ...
    @property
    def ukf_runs(self) -> int:
        ...
class PfOptions:
    """
    Settings of ParticleFilter.
    """
    resampling: PfResampling
    seed: int
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, num_particles: typing.SupportsInt | typing.SupportsIndex = 10000, resampling: PfResampling = PfResampling.Systematic, ess_threshold: typing.SupportsFloat | typing.SupportsIndex = 0.5, merge_threshold: typing.SupportsFloat | typing.SupportsIndex = -1.0, threads: typing.SupportsInt | typing.SupportsIndex = 1, seed: int = 0) -> None:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def ess_threshold(self) -> float:
        ...
    @ess_threshold.setter
    def ess_threshold(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def merge_threshold(self) -> float:
        ...
    @merge_threshold.setter
    def merge_threshold(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def num_particles(self) -> int:
        ...
    @num_particles.setter
    def num_particles(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def threads(self) -> int:
        ...
    @threads.setter
    def threads(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class PfSnapshot:
    """
    What a ParticleFilter carries from one step to the next (ParticleFilter.save / ParticleFilter.restore): a checkpoint, and what pickling a ParticleFilter stores. Checked by ParticleFilter.restore.
    """
    GENERATOR_WORDS: typing.ClassVar[int] = 87
    def __init__(self, particles: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], situations: typing.Annotated[numpy.typing.ArrayLike, numpy.int32, "[m, n]"], log_weights: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], situation_probabilities: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], estimate: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], covariance: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], position_variance: typing.SupportsFloat | typing.SupportsIndex, generators: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], time: typing.SupportsFloat | typing.SupportsIndex, step: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        particles (n, M), situations (B, M) condition indices, log_weights (M,) normalised, situation_probabilities (B, N_z), estimate (n,), covariance (n, n), position_variance (eq. 31's input), generators (GENERATOR_WORDS words per thread, as save() gives them), time (s), step.
        """
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Weighted covariance after the last weighting.
        """
    @property
    def estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Weighted mean after the last weighting.
        """
    @property
    def generators(self) -> list[int]:
        """
        The threads' random generators: GENERATOR_WORDS 64-bit words each (opaque).
        """
    @property
    def log_weights(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (M,) normalised log weights.
        """
    @property
    def particles(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (n, M) states.
        """
    @property
    def position_variance(self) -> float:
        """
        Its position variance as the step computed it (eq. 31's d_min).
        """
    @property
    def situation_probabilities(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z).
        """
    @property
    def situations(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, n]"]:
        """
        (B, M) condition indices (0 = LOS).
        """
    @property
    def step(self) -> int:
        ...
    @property
    def time(self) -> float:
        ...
class PfStepInfo:
    """
    What one PF step reports.
    """
    def __repr__(self) -> str:
        ...
    @property
    def ess(self) -> float:
        ...
    @property
    def log_likelihood(self) -> float:
        ...
    @property
    def merged(self) -> int:
        ...
    @property
    def resampled(self) -> bool:
        ...
class Rbpf:
    """
    Rao-Blackwellized particle filter with UKF bank and merge/select (Huerta Sec. V-A/B).
    """
    def __init__(self, motion: typing.Any, measurements: nlosloc._core.models.MeasurementStack, sight: nlosloc._core.situation.SightProcess, quality: nlosloc._core.situation.QualityModel, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], options: RbpfOptions = ..., t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def belief(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        The Gaussian summary as a tuple (mean (n,), cov (n, n)).
        """
    def check_inputs(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        Raises the ValueError a step with y (m,) and o (B,) would raise, changing nothing (run() checks every row this way before its first step).
        """
    def log_weight(self, i: int) -> float:
        """
        Normalised log weight of particle i.
        """
    def particle_cov(self, i: int) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    def particle_mean(self, i: int) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    def particle_situation(self, i: int) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        ...
    def reset(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        Restarts from N(mean, cov) at time t0 (validated; a rejected call changes nothing).
        """
    def restore(self, snapshot: RbpfSnapshot) -> None:
        """
        Sets the filter to a snapshot (checked first: ValueError naming the field, nothing changed).
        """
    def run(self, Y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], O: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> dict:
        """
        step() over the rows of Y (T, m) and O (T, B), GIL released. Returns a dict of mean (T, n), cov (T, n, n), situation_probabilities (T, B, N_z), log_likelihood (T,).
        """
    def save(self) -> RbpfSnapshot:
        """
        A snapshot of everything the next step depends on (the joint PF's: its random generators too): restore() of it into a filter of this class with the same models and options makes that one step on exactly as this one.
        """
    def sight_estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        Most probable condition per anchor (B,).
        """
    def step(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> RbpfStepInfo:
        """
        One iteration with measurements y (m,) and quality statistics o (B,).
        """
    @property
    def children_per_particle(self) -> int:
        ...
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Covariance (n, n) of the posterior (moment-matched mixture, eq. 27).
        """
    @property
    def estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        State estimate (n,) (Huerta eq. 28 for the RBPF).
        """
    @property
    def measurements(self) -> nlosloc._core.models.MeasurementStack:
        """
        The measurement stack (a copy).
        """
    @property
    def motion(self) -> typing.Any:
        """
        The motion model (a copy).
        """
    @property
    def num_anchors(self) -> int:
        ...
    @property
    def num_conditions(self) -> int:
        ...
    @property
    def num_particles(self) -> int:
        ...
    @property
    def options(self) -> RbpfOptions:
        """
        The settings (a copy).
        """
    @property
    def quality(self) -> nlosloc._core.situation.QualityModel:
        """
        The situation.QualityModel it was built with (a copy).
        """
    @property
    def sight_process(self) -> nlosloc._core.situation.SightProcess:
        """
        The situation.SightProcess it was built with (a copy).
        """
    @property
    def situation_probabilities(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z) P(s_b = z | data).
        """
    @property
    def step_index(self) -> int:
        """
        Steps taken since the last reset.
        """
    @property
    def time(self) -> float:
        """
        Time of the estimate (s).
        """
    @property
    def weights(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class ParticleFilter:
    """
    Joint bootstrap particle filter over (x, s) (Huerta Sec. VI-B, PF).
    """
    def __init__(self, motion: typing.Any, measurements: nlosloc._core.models.MeasurementStack, sight: nlosloc._core.situation.SightProcess, quality: nlosloc._core.situation.QualityModel, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], options: PfOptions = ..., t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def belief(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        The Gaussian summary as a tuple (mean (n,), cov (n, n)).
        """
    def check_inputs(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        Raises the ValueError a step with y (m,) and o (B,) would raise, changing nothing (run() checks every row this way before its first step).
        """
    def reset(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        Restarts from N(mean, cov) at time t0 (validated; a rejected call changes nothing).
        """
    def restore(self, snapshot: PfSnapshot) -> None:
        """
        Sets the filter to a snapshot (checked first: ValueError naming the field, nothing changed).
        """
    def run(self, Y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], O: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> dict:
        """
        As Rbpf.run.
        """
    def save(self) -> PfSnapshot:
        """
        A snapshot of everything the next step depends on (the joint PF's: its random generators too): restore() of it into a filter of this class with the same models and options makes that one step on exactly as this one.
        """
    def sight_estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        Most probable condition per anchor (B,).
        """
    def step(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> PfStepInfo:
        ...
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Covariance (n, n) of the posterior (moment-matched mixture, eq. 27).
        """
    @property
    def estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        State estimate (n,) (Huerta eq. 28 for the RBPF).
        """
    @property
    def log_weights(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def measurements(self) -> nlosloc._core.models.MeasurementStack:
        """
        The measurement stack (a copy).
        """
    @property
    def motion(self) -> typing.Any:
        """
        The motion model (a copy).
        """
    @property
    def num_particles(self) -> int:
        ...
    @property
    def options(self) -> PfOptions:
        """
        The settings (a copy).
        """
    @property
    def particles(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (n, M) particle states (a copy).
        """
    @property
    def quality(self) -> nlosloc._core.situation.QualityModel:
        """
        The situation.QualityModel it was built with (a copy).
        """
    @property
    def sight_process(self) -> nlosloc._core.situation.SightProcess:
        """
        The situation.SightProcess it was built with (a copy).
        """
    @property
    def situation_probabilities(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z) P(s_b = z | data).
        """
    @property
    def situations(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, n]"]:
        ...
    @property
    def step_index(self) -> int:
        """
        Steps taken since the last reset.
        """
    @property
    def time(self) -> float:
        """
        Time of the estimate (s).
        """
    @property
    def uses_avx2(self) -> bool:
        """
        Whether the pass runs its AVX2 build: a portable x86-64 build on a CPU with AVX2, with NLOSLOC_NO_AVX2 unset (or '0') in the environment when the filter was built. Either way a step's result is the same bit for bit.
        """
class Iukf:
    """
    Improved UKF (Huerta Table VI, N_z conditions as Grisales eqs. 36-37): per-anchor forward filter on the quality statistics, one noise set per condition weighted by its probabilities.
    """
    def __init__(self, motion: typing.Any, measurements: nlosloc._core.models.MeasurementStack, sight: nlosloc._core.situation.SightProcess, quality: nlosloc._core.situation.QualityModel, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], scheme: nlosloc._core.core.SigmaScheme = ..., t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def belief(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        The Gaussian summary as a tuple (mean (n,), cov (n, n)).
        """
    def check_inputs(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        Raises the ValueError a step with y (m,) and o (B,) would raise, changing nothing (run() checks every row this way before its first step).
        """
    def predict(self) -> None:
        ...
    def run(self, Y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], O: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> dict:
        """
        As Rbpf.run.
        """
    def set_belief(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Replaces the belief (validated: finite mean, symmetric positive definite cov).
        """
    def sight_estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        Most probable condition per anchor (B,).
        """
    def step(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], o: typing.Any = None, *, sight: typing.Any = None) -> nlosloc._core.filters.StepResult:
        """
        With o (B,): step_quality(y, o). With sight= (B,) ints: the C++ step(y, sight), a known situation (one-hot probabilities: the plain UKF). Returns a StepResult.
        """
    def step_quality(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> nlosloc._core.filters.StepResult:
        """
        predict, forward filter with o (B,), update with y (m,); a rejected call changes nothing. Returns a StepResult.
        """
    def update_with_probabilities(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], gamma: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> nlosloc._core.filters.StepResult:
        """
        Update with explicit (B, N_z) condition probabilities.
        """
    @property
    def cov(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Covariance (n, n) of the posterior (moment-matched mixture, eq. 27).
        """
    @property
    def dim(self) -> int:
        """
        Size n of the state.
        """
    @property
    def estimate(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        State estimate (n,) (Huerta eq. 28 for the RBPF).
        """
    @property
    def forward(self) -> nlosloc._core.situation.ForwardFilter:
        """
        The forward filter of the sight (not a copy).
        """
    @property
    def mean(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def measurements(self) -> nlosloc._core.models.MeasurementStack:
        """
        The measurement stack (a copy).
        """
    @property
    def motion(self) -> typing.Any:
        """
        The motion model (a copy).
        """
    @property
    def scheme(self) -> nlosloc._core.core.SigmaScheme:
        """
        The sigma-point scheme.
        """
    @property
    def situation_probabilities(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z) P(s_b = z | data).
        """
    @property
    def time(self) -> float:
        """
        Time of the estimate (s).
        """
def decode_situation(key: int, num_conditions: typing.SupportsInt | typing.SupportsIndex, num_anchors: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
    """
    The situation vector (B,) of a key (inverse of encode_situation).
    """
def default_merge_threshold(position_variance: typing.SupportsFloat | typing.SupportsIndex, num_particles: typing.SupportsInt | typing.SupportsIndex) -> float:
    """
    d_min = sigma^2 / (10 M), Huerta eq. (31).
    """
def encode_situation(sight: typing.Any, num_conditions: typing.SupportsInt | typing.SupportsIndex) -> int:
    """
    Key of a situation vector (B,) of conditions in [0, N_z): its base-N_z digits, anchor 0 least significant (the keys of merge_greedy and of the RBPF's particles).
    """
def enumerate_best(A: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], limit: int) -> tuple:
    """
    The `limit` situation vectors with the largest sum_b A[b, s_b], in decreasing order, ties by the smaller rank vector (exact best-first search: the RBPF's bounded enumeration). Returns (keys, sums) as enumerate_offspring.
    """
def enumerate_offspring(A: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], limit: int) -> tuple:
    """
    The children of one particle as the RBPF expands them (Huerta eq. 23): every situation vector when N_z^B <= limit, in key order, else the `limit` with the largest sum_b A[b, s_b] (best first, enumerate_best). A (B, N_z): log factors per anchor and condition (finite or -inf). Returns (keys (K,) uint64 as encode_situation, sums (K,)).
    """
def merge_greedy(keys: collections.abc.Sequence[int], means: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], logw: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], d_min: typing.SupportsFloat | typing.SupportsIndex, with_pairs: bool = False, threads: typing.SupportsInt | typing.SupportsIndex = 1) -> tuple:
    """
    Greedy merge of eqs. (29)-(30): keys (K,) situation keys, means (n, K), logw (K,). Returns (new logw, number absorbed), and with with_pairs=True also an (absorbed, 2) int array of (absorber, absorbed) pairs in merge order (each absorbed particle once; its weight moved is its input weight). threads > 1 runs merge_greedy_parallel (the joint PF's merge; keys below 2^32, no pairs): the same result on a pool of that many threads.
    """
def pf_simd_lanes() -> int:
    """
    Doubles per SIMD packet in ParticleFilter's inner loops for this build of the module: 2 on x86-64 by default, 4 (AVX, AVX2) or 8 (AVX-512) when built with -Ccmake.define.NLOSLOC_NATIVE=ON on such a CPU.
    """
def select_top(logw: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], M: typing.SupportsInt | typing.SupportsIndex) -> list[int]:
    """
    Indices of the (at most) M entries of logw with the largest finite log weights, heaviest first, ties by index (the prune step of Huerta Sec. V-A.3; -inf entries are never kept).
    """
def situation_count(num_conditions: typing.SupportsInt | typing.SupportsIndex, num_anchors: typing.SupportsInt | typing.SupportsIndex) -> int:
    """
    N_z^B (0 when above 2^62).
    """
def systematic_resample(w: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], M: typing.SupportsInt | typing.SupportsIndex, u0: typing.SupportsFloat | typing.SupportsIndex) -> list[int]:
    """
    Ancestor indices of systematic resampling (normalised w).
    """
