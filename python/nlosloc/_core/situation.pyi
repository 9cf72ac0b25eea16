"""
Sight (LOS/NLOS) Markov models, quality likelihoods, HMM filter.
"""
from __future__ import annotations
import collections.abc
import nlosloc._core.core
import nlosloc._core.noise
import numpy
import numpy.typing
import typing
__all__: list[str] = ['ForwardFilter', 'ForwardFilterSnapshot', 'QualityModel', 'SightModel', 'SightProcess', 'SpeedModel', 'speed_switch_probability', 'speed_transition_memoryless', 'speed_transition_multiple', 'speed_transition_single', 'transversal_speed', 'transversal_speeds']
class SpeedModel:
    """
    Form of the speed-dependent two-state chain.
    
    Members:
    
      Single : Huerta eq. (15): at most one change per interval
    
      Multiple : Huerta eq. (17): any number of changes per interval
    
      Memoryless : Huerta eq. (18): rows (p_L, p_N)
    """
    Memoryless: typing.ClassVar[SpeedModel]
    Multiple: typing.ClassVar[SpeedModel]
    Single: typing.ClassVar[SpeedModel]
    __members__: typing.ClassVar[dict[str, SpeedModel]]
    @typing.overload
    def __eq__(self, other: SpeedModel) -> bool:
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
    def __ne__(self, other: SpeedModel) -> bool:
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
class SightModel:
    """
    Sight chain of one anchor: fixed N_z x N_z or speed-dependent LOS/NLOS.
    """
    @staticmethod
    def fixed(transition: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], k_sight: typing.SupportsInt | typing.SupportsIndex = 1, initial: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] = ...) -> SightModel:
        """
        Fixed row-stochastic matrix (N_z, N_z); changes only every k_sight steps (Grisales eq. 16). initial (N_z,) prior of s_0, empty: stationary distribution.
        """
    @staticmethod
    def speed_dependent(mean_los: typing.SupportsFloat | typing.SupportsIndex, mean_nlos: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, form: SpeedModel = SpeedModel.Multiple, initial: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] = ...) -> SightModel:
        """
        LOS/NLOS chain from the transversal speed (Huerta eqs. 14-18); mean lengths in m, dt in s.
        """
    def is_change_step(self, k: typing.SupportsInt | typing.SupportsIndex) -> bool:
        ...
    def sample_initial(self, rng: nlosloc._core.core.Rng) -> int:
        ...
    def sample_next(self, current: typing.SupportsInt | typing.SupportsIndex, k: typing.SupportsInt | typing.SupportsIndex, w: typing.SupportsFloat | typing.SupportsIndex, rng: nlosloc._core.core.Rng) -> int:
        """
        Draws s_k given s_{k-1} = current.
        """
    def transition(self, k: typing.SupportsInt | typing.SupportsIndex, w: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Transition matrix of the step k-1 -> k at transversal speed w (m/s).
        """
    @property
    def base_matrix(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def dt(self) -> float:
        """
        Interval (s) of a speed-dependent chain; 0 for a fixed one.
        """
    @property
    def form(self) -> SpeedModel:
        """
        Form of a speed-dependent chain.
        """
    @property
    def initial(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def is_speed_dependent(self) -> bool:
        ...
    @property
    def k_sight(self) -> int:
        ...
    @property
    def mean_los(self) -> float:
        """
        Mean LOS length (m); 0 for a fixed chain.
        """
    @property
    def mean_nlos(self) -> float:
        """
        Mean NLOS length (m); 0 for a fixed chain.
        """
    @property
    def num_conditions(self) -> int:
        ...
class SightProcess:
    """
    Independent sight chains of B anchors (Huerta eq. 9).
    """
    @typing.overload
    def __init__(self, models: collections.abc.Sequence[SightModel]) -> None:
        ...
    @typing.overload
    def __init__(self, model: SightModel, num_anchors: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def log_transition(self, from: typing.Annotated[numpy.typing.ArrayLike, numpy.int32, "[m, 1]"], to: typing.Annotated[numpy.typing.ArrayLike, numpy.int32, "[m, 1]"], k: typing.SupportsInt | typing.SupportsIndex, speeds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> float:
        """
        log p(s_k = to | s_{k-1} = from), eq. (9).
        """
    def model(self, b: typing.SupportsInt | typing.SupportsIndex) -> SightModel:
        ...
    def sample_initial(self, rng: nlosloc._core.core.Rng) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        ...
    def sample_next(self, current: typing.Annotated[numpy.typing.ArrayLike, numpy.int32, "[m, 1]"], k: typing.SupportsInt | typing.SupportsIndex, speeds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], rng: nlosloc._core.core.Rng) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        Draws s_k (B,) from s_{k-1}; speeds (B,) transversal speeds (may be empty if unused).
        """
    @property
    def is_speed_dependent(self) -> bool:
        ...
    @property
    def num_anchors(self) -> int:
        ...
    @property
    def num_conditions(self) -> int:
        ...
class QualityModel:
    """
    Quality-statistic likelihoods p(o | s = z), one distribution per z.
    """
    def __init__(self, per_condition: collections.abc.Sequence[nlosloc._core.noise.Distribution]) -> None:
        ...
    def distribution(self, z: typing.SupportsInt | typing.SupportsIndex) -> nlosloc._core.noise.Distribution:
        ...
    @typing.overload
    def log_likelihood(self, o: typing.SupportsFloat | typing.SupportsIndex, z: typing.SupportsInt | typing.SupportsIndex) -> float:
        """
        log p(o | s = z); 0 for NaN (missing).
        """
    @typing.overload
    def log_likelihood(self, o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], s: typing.Any) -> float:
        """
        log p(o | s) = sum_b log p(o_b | s_b) for o (B,) and s (B,).
        """
    def log_likelihood_table(self, o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z) table of log p(o_b | s_b = z).
        """
    def log_likelihoods(self, o: typing.SupportsFloat | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        log p(o | s = z) for every z, shape (N_z,).
        """
    @typing.overload
    def sample(self, z: typing.SupportsInt | typing.SupportsIndex, rng: nlosloc._core.core.Rng) -> float:
        """
        One statistic drawn under condition z (simulation).
        """
    @typing.overload
    def sample(self, s: typing.Any, rng: nlosloc._core.core.Rng) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        One statistic per anchor for situation s (B,).
        """
    @property
    def num_conditions(self) -> int:
        ...
class ForwardFilterSnapshot:
    """
    State saved by ForwardFilter.save().
    """
    def __init__(self, gamma: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], pred: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], k: typing.SupportsInt | typing.SupportsIndex, log_evidence: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        A state to restore(): gamma and pred (B, N_z) rows of probabilities (>= 0, summing to 1), step index k >= 0, last log evidence (restore() checks the shapes against the filter).
        """
    @property
    def gamma(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z) probabilities.
        """
    @property
    def k(self) -> int:
        """
        Step index.
        """
    @property
    def log_evidence(self) -> float:
        """
        Last log evidence.
        """
    @property
    def pred(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z) predicted probabilities.
        """
class ForwardFilter:
    """
    Per-anchor HMM forward filter of the sight (Huerta eqs. 35-38).
    """
    def __init__(self, process: SightProcess, quality: QualityModel) -> None:
        ...
    def argmax(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        ...
    def predict(self, speeds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] = ...) -> None:
        """
        Prediction, eq. (36).
        """
    def reset(self) -> None:
        ...
    def restore(self, snapshot: ForwardFilterSnapshot) -> None:
        """
        Restores a snapshot from save() (shapes are checked).
        """
    def save(self) -> ForwardFilterSnapshot:
        """
        Snapshot of the mutable state (probabilities, step, evidence), to undo steps with restore().
        """
    def set_probabilities(self, gamma: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> None:
        """
        Replaces the probabilities (B, N_z) (rows >= 0 summing to 1); also the prior of the next update.
        """
    def step(self, o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], speeds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] = ...) -> float:
        """
        predict(speeds) then update(o); a rejected call changes nothing.
        """
    def update(self, o: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> float:
        """
        Update with o (B,) (NaN = missing), eqs. (37)-(38); returns log p(o_t | o_1:t-1).
        """
    @property
    def last_log_evidence(self) -> float:
        """
        log p(o_t | o_1:t-1) of the last update.
        """
    @property
    def num_anchors(self) -> int:
        ...
    @property
    def num_conditions(self) -> int:
        ...
    @property
    def predicted(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def probabilities(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (B, N_z) P(s_b = z | o_b,1:t).
        """
    @property
    def process(self) -> SightProcess:
        """
        The sight chains (a copy).
        """
    @property
    def quality(self) -> QualityModel:
        """
        The quality likelihoods (a copy).
        """
    @property
    def step_index(self) -> int:
        ...
def speed_switch_probability(model: SightModel, current: typing.SupportsInt | typing.SupportsIndex, w: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    Probability that a speed-dependent chain leaves `current` in one interval at transversal speed w (the off-diagonal entry of eq. 15, 17 or 18, in closed form).
    """
def speed_transition_memoryless(mean_los: typing.SupportsFloat | typing.SupportsIndex, mean_nlos: typing.SupportsFloat | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
    """
    2x2 memoryless matrix of Huerta eq. (18), rows (p_L, p_N).
    """
def speed_transition_multiple(w: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, mean_los: typing.SupportsFloat | typing.SupportsIndex, mean_nlos: typing.SupportsFloat | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
    """
    2x2 transition matrix of Huerta eq. (17).
    """
def speed_transition_single(w: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, mean_los: typing.SupportsFloat | typing.SupportsIndex, mean_nlos: typing.SupportsFloat | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
    """
    2x2 [LOS, NLOS] transition matrix of Huerta eq. (15).
    """
def transversal_speed(p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], v: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> float:
    """
    Transversal speed of a mobile at p with velocity v w.r.t. an anchor at q (Huerta eq. 10), m/s.
    """
def transversal_speeds(p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], v: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], anchors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    Transversal speed (Huerta eq. 10) w.r.t. every anchor (rows of anchors (B, D)), shape (B,).
    """
