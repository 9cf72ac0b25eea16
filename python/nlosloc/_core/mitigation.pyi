"""
Ke and Wu QP-bias EKF, bias-augmented EKF, QP adapter.
"""
from __future__ import annotations
import collections.abc
import nlosloc._core.filters
import nlosloc._core.models
import numpy
import numpy.typing
import typing
__all__: list[str] = ['BiasAugmentedEkf', 'BiasAugmentedEkfOptions', 'BiasEstimate', 'BiasEstimator', 'BiasReference', 'BoxQp', 'BoxQpSettings', 'FLAG_BOUNDS_CLAMPED', 'FLAG_DEGENERATE_GEOMETRY', 'FLAG_MISSING_ROWS', 'FLAG_QP_FAILED', 'FLAG_REFERENCE_FALLBACK', 'FLAG_UPDATE_REJECTED', 'MitigationStep', 'QpBiasEkf', 'QpBiasEkfOptions', 'QpResult', 'QpStatus', 'RangeNoise', 'ReferenceKind', 'ReferencePoint', 'have_default_box_qp', 'have_proxsuite_box_qp', 'make_box_qp', 'reference_point']
class QpStatus:
    """
    Outcome of BoxQp.solve.
    
    Members:
    
      Solved
    
      MaxIterations
    
      PrimalInfeasible
    
      DualInfeasible
    
      Failed
    """
    DualInfeasible: typing.ClassVar[QpStatus]
    Failed: typing.ClassVar[QpStatus]
    MaxIterations: typing.ClassVar[QpStatus]
    PrimalInfeasible: typing.ClassVar[QpStatus]
    Solved: typing.ClassVar[QpStatus]
    __members__: typing.ClassVar[dict[str, QpStatus]]
    @typing.overload
    def __eq__(self, other: QpStatus) -> bool:
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
    def __ne__(self, other: QpStatus) -> bool:
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
class BoxQpSettings:
    """
    Accuracy settings of the box-QP solvers (DESIGN.md).
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        BoxQpSettings(**fields): the defaults, with any of the fields (eps_abs, check_duality_gap, eps_duality_gap_abs, max_iter, compute_preconditioner) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def check_duality_gap(self) -> bool:
        """
        Also require a small gap.
        """
    @check_duality_gap.setter
    def check_duality_gap(self, arg1: bool) -> None:
        ...
    @property
    def compute_preconditioner(self) -> bool:
        """
        Ruiz equilibration before each solve (off: problems are pre-scaled).
        """
    @compute_preconditioner.setter
    def compute_preconditioner(self, arg1: bool) -> None:
        ...
    @property
    def eps_abs(self) -> float:
        """
        Absolute residual tolerance (> 0).
        """
    @eps_abs.setter
    def eps_abs(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def eps_duality_gap_abs(self) -> float:
        """
        Duality-gap tolerance.
        """
    @eps_duality_gap_abs.setter
    def eps_duality_gap_abs(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_iter(self) -> int:
        """
        Iteration limit (>= 1).
        """
    @max_iter.setter
    def max_iter(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class QpResult:
    """
    What one BoxQp.solve reports; the minimiser is BoxQp.x.
    """
    def __repr__(self) -> str:
        ...
    def ok(self) -> bool:
        """
        True when solved.
        """
    @property
    def iterations(self) -> int:
        ...
    @property
    def objective(self) -> float:
        """
        1/2 x^T H x + g^T x at x.
        """
    @property
    def status(self) -> QpStatus:
        ...
class BoxQp:
    """
    Box-constrained convex QP: minimise 1/2 x^T H x + g^T x, lower <= x <= upper (Ke & Wu eq. 14). Build one with make_box_qp(n).
    """
    def __copy__(self) -> BoxQp:
        ...
    def __deepcopy__(self, memo: dict) -> BoxQp:
        ...
    def __getstate__(self) -> tuple:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def clone(self) -> BoxQp:
        """
        An independent solver that solves as this one would (BoxQp::clone); also copy.copy and copy.deepcopy.
        """
    def solve(self, H: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], g: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], lower: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], upper: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> QpResult:
        """
        Solves the QP. H (n, n) symmetric (to 1e-10 of its largest |entry|) positive semidefinite (to n 1e-12 of its largest diagonal entry), g, lower, upper (n,) finite, lower <= upper, else ValueError naming the argument; returns QpResult.
        """
    @property
    def active_set(self) -> typing.Any:
        """
        'enumeration' only (None otherwise): the active set its next solve tries first, per variable 0 free, 1 at its lower bound, 2 at its upper bound (on a singular H it picks the minimiser returned).
        """
    @active_set.setter
    def active_set(self, arg1: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> None:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def settings(self) -> BoxQpSettings | None:
        """
        The BoxQpSettings it was made with (a copy); None for 'failing'.
        """
    @property
    def size(self) -> int:
        ...
    @property
    def x(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Minimiser of the last solve (n,).
        """
class ReferenceKind:
    """
    How the reference point X0 was obtained (Sec. 3).
    
    Members:
    
      FeasibleVertices
    
      Hint
    
      LeastSquares
    """
    FeasibleVertices: typing.ClassVar[ReferenceKind]
    Hint: typing.ClassVar[ReferenceKind]
    LeastSquares: typing.ClassVar[ReferenceKind]
    __members__: typing.ClassVar[dict[str, ReferenceKind]]
    @typing.overload
    def __eq__(self, other: ReferenceKind) -> bool:
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
    def __ne__(self, other: ReferenceKind) -> bool:
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
class BiasReference:
    """
    Residual and covariance of eq. (14) in QpBiasEkf.
    
    Members:
    
      Prediction
    
      Snapshot
    """
    Prediction: typing.ClassVar[BiasReference]
    Snapshot: typing.ClassVar[BiasReference]
    __members__: typing.ClassVar[dict[str, BiasReference]]
    @typing.overload
    def __eq__(self, other: BiasReference) -> bool:
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
    def __ne__(self, other: BiasReference) -> bool:
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
class RangeNoise:
    """
    Range noise std_i = sigma0 + relative * d_i (m).
    """
    def __init__(self, sigma0: typing.SupportsFloat | typing.SupportsIndex = 50.0, relative: typing.SupportsFloat | typing.SupportsIndex = 0.0, min_std: typing.SupportsFloat | typing.SupportsIndex = 0.001) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def std_at(self, d: typing.SupportsFloat | typing.SupportsIndex) -> float:
        """
        Noise std at distance d (m).
        """
    def validate(self, name: str = 'noise') -> None:
        """
        Raises ValueError naming the field (as `name`.field) unless sigma0, relative >= 0 and min_std > 0, all finite.
        """
    @property
    def min_std(self) -> float:
        ...
    @min_std.setter
    def min_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def relative(self) -> float:
        ...
    @relative.setter
    def relative(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma0(self) -> float:
        ...
    @sigma0.setter
    def sigma0(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class ReferencePoint:
    """
    Reference point X0 of Sec. 3.
    """
    def __repr__(self) -> str:
        ...
    @property
    def kind(self) -> ReferenceKind:
        ...
    @property
    def point(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def vertices(self) -> int:
        ...
class BiasEstimate:
    """
    Result of BiasEstimator.estimate (Sec. 3).
    """
    def __repr__(self) -> str:
        ...
    @property
    def bias(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        b^ of eq. (14) (M,), m.
        """
    @property
    def flags(self) -> int:
        """
        FLAG_* bits of the fallbacks taken.
        """
    @property
    def lower(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Lower bounds (eq. 14).
        """
    @property
    def qp(self) -> QpResult:
        ...
    @property
    def reference(self) -> ReferencePoint:
        ...
    @property
    def upper(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Upper bounds (eq. 15, after the documented clamp).
        """
    @property
    def x_tilde(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Eq. (11).
        """
class BiasEstimator:
    """
    Ke & Wu Sec. 3 NLOS bias estimation for fixed anchors.
    """
    def __init__(self, anchors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], solver: typing.Any = 'default', settings: BoxQpSettings = ...) -> None:
        """
        anchors (M, 2), M >= 3. solver: a name (as make_box_qp), a BoxQp of size M (a copy is used) or an object with solve(H, g, lower, upper) returning the minimiser (M,) or None (see QpBiasEkf).
        """
    def estimate(self, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], variances: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], hint: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] | None = None) -> BiasEstimate:
        """
        Biases of ranges z (M,) with noise variances (M,) (eqs. 9-15); returns a BiasEstimate copy.
        """
    def estimate_from_innovation(self, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], innovation: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], D: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> BiasEstimate:
        """
        Eqs. (12)-(15) referenced to a tracker's prediction: r = innovation (M,) (eq. 26), L = I, Sigma_v = D (M, M) (eq. 27: F P F^T + R), bounds from the ranges z (M,); returns a BiasEstimate copy. D must be finite, symmetric and positive definite, else ValueError naming D (the estimator unchanged).
        """
    @property
    def H0(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Eq. (10), (M, 2).
        """
    @property
    def L(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Eq. (12), (M, M).
        """
    @property
    def U(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Eq. (11), (2, M).
        """
    @property
    def anchors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def last(self) -> BiasEstimate:
        """
        The last estimate (a BiasEstimate copy).
        """
    @property
    def qp_gradient(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def qp_hessian(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def r(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Eq. (12) bias metric.
        """
    @property
    def sigma_v(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Eq. (13), L R L^T.
        """
    @property
    def sigma_v_ginv(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        R^-1 L.
        """
    @property
    def size(self) -> int:
        ...
    @property
    def soft_threshold(self) -> float:
        """
        lambda of the soft threshold of estimate_from_innovation (0 = eq. 14 as written): with diagonal D, b_i = clip(r_i - lambda sqrt(D_ii), 0, b_i^U).
        """
    @soft_threshold.setter
    def soft_threshold(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def solver(self) -> typing.Any:
        """
        A copy of the eq. (14) solver: a BoxQp, or copy.deepcopy of your own solver object.
        """
    @property
    def solver_name(self) -> str:
        """
        Name of the eq. (14) solver in use.
        """
    @property
    def sparsity(self) -> float:
        """
        L1 tie-break weight added to eq. (14) (0 = plain eq. 14).
        """
    @sparsity.setter
    def sparsity(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def y(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Eq. (9) linearised measurement.
        """
class QpBiasEkfOptions:
    """
    Options of QpBiasEkf.
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        QpBiasEkfOptions(**fields): the defaults, with any of the fields (gamma, noise, mitigate, always_estimate, sparsity, reference, drop_free_rows, soft_threshold) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    def validate(self) -> None:
        """
        Raises ValueError naming the field (options.gamma, options.noise.*, options.sparsity, options.reference, options.soft_threshold) that QpBiasEkf would refuse, with the message QpBiasEkf gives; the fields are not checked when set.
        """
    @property
    def always_estimate(self) -> bool:
        """
        Run the QP every step.
        """
    @always_estimate.setter
    def always_estimate(self, arg1: bool) -> None:
        ...
    @property
    def drop_free_rows(self) -> bool:
        """
        Leave rows whose b^_i is strictly inside its box out of the update (default True).
        """
    @drop_free_rows.setter
    def drop_free_rows(self, arg1: bool) -> None:
        ...
    @property
    def gamma(self) -> float:
        """
        Scaling factor of eq. (32), >= 1.
        """
    @gamma.setter
    def gamma(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def mitigate(self) -> bool:
        """
        False: plain EKF (eqs. 20-24).
        """
    @mitigate.setter
    def mitigate(self, arg1: bool) -> None:
        ...
    @property
    def noise(self) -> RangeNoise:
        """
        RangeNoise of R(k).
        """
    @noise.setter
    def noise(self, arg1: RangeNoise) -> None:
        ...
    @property
    def reference(self) -> BiasReference:
        """
        BiasReference.Prediction (default: r = innovation, Sigma_v = eq. 27) or Snapshot (Sec. 3).
        """
    @reference.setter
    def reference(self, arg1: BiasReference) -> None:
        ...
    @property
    def soft_threshold(self) -> float:
        """
        PREDICTION only: lambda of an L1 term on eq. (14) keeping rows within about lambda standard deviations as LOS (0 = eq. 14 as written; not in the paper).
        """
    @soft_threshold.setter
    def soft_threshold(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sparsity(self) -> float:
        """
        L1 tie-break of eq. (14) (SNAPSHOT only).
        """
    @sparsity.setter
    def sparsity(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class MitigationStep:
    """
    What one QpBiasEkf update reports.
    """
    def __repr__(self) -> str:
        ...
    @property
    def bias_estimated(self) -> bool:
        ...
    @property
    def filter(self) -> nlosloc._core.filters.StepResult:
        """
        StepResult (log-likelihood, rows used, status).
        """
    @property
    def flags(self) -> int:
        ...
    @property
    def innovation_sq(self) -> float:
        """
        alpha^T alpha (eq. 31).
        """
    @property
    def nlos(self) -> bool:
        """
        H1 of eq. (32).
        """
    @property
    def rows_dropped(self) -> int:
        """
        Rows left out because b^_i was strictly inside its box.
        """
    @property
    def threshold(self) -> float:
        """
        gamma Tr[F P F^T + R] (eq. 32).
        """
class QpBiasEkf:
    """
    Ke & Wu 2011 proposed tracker: EKF with QP-estimated NLOS biases (eq. 25) and the innovation test of eqs. (31)-(32). State [x, y, vx, vy].
    """
    def __copy__(self) -> QpBiasEkf:
        ...
    def __deepcopy__(self, memo: dict) -> QpBiasEkf:
        """
        An independent tracker in the same state, the last step's report included (its solver copied as QpBiasEkf.solver).
        """
    def __init__(self, motion: nlosloc._core.models.ConstantVelocity2, anchors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], options: QpBiasEkfOptions = ..., solver: typing.Any = 'default', t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        motion: models.ConstantVelocity2 (eq. 16); anchors (M, 2); initial mean (4,), cov (4, 4). solver: 'default' (its own choice), 'enumeration', 'proxsuite', 'failing', a BoxQp of size M (make_box_qp; the tracker uses a copy), or your own: an object with solve(H, g, lower, upper) returning the minimiser (M,) of 1/2 x^T H x + g^T x on lower <= x <= upper, or None when it finds none (a failure: the tracker's fallback). It is called with the GIL; a result of the wrong shape or outside the box raises ValueError and leaves the tracker unchanged, as does an exception raised inside it. Copies of the tracker (the Monte Carlo workers') get copy.deepcopy of it.
        """
    def belief(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        The belief as a tuple (mean (4,), cov (4, 4)).
        """
    def predict(self) -> None:
        """
        Eqs. (20)-(21).
        """
    def run(self, Z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], first_is_update: bool = True) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Runs over ranges Z (T, M); returns the means (T, 4). Row 0 is an update only by default. Every row is checked before the first step.
        """
    def set_belief(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Replaces the belief and, when t is given, the time; clears the last bias and decision.
        """
    def step(self, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> MitigationStep:
        """
        predict() then update(z).
        """
    def update(self, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> MitigationStep:
        """
        Update with ranges z (M,), NaN = missing.
        """
    @property
    def anchors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def bias(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        b^ of the last update (M,) (a copy).
        """
    @property
    def bias_estimator(self) -> BiasEstimator:
        """
        A copy of its Sec. 3 estimator: the last QP's bounds, reference point, status and intermediates (BiasEstimator.last, .qp_hessian, ...).
        """
    @property
    def cov(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def last_step(self) -> MitigationStep:
        ...
    @property
    def mean(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def motion(self) -> nlosloc._core.models.ConstantVelocity2:
        """
        The motion model (a copy).
        """
    @property
    def nlos_detected(self) -> bool:
        ...
    @property
    def num_anchors(self) -> int:
        ...
    @property
    def options(self) -> QpBiasEkfOptions:
        ...
    @property
    def solver(self) -> typing.Any:
        """
        A copy of the eq. (14) solver: a BoxQp, or copy.deepcopy of your own solver object (what pickling the tracker stores).
        """
    @property
    def solver_name(self) -> str:
        """
        Name of the eq. (14) solver in use ("enumeration", "proxsuite-dense", ...).
        """
    @property
    def time(self) -> float:
        ...
class BiasAugmentedEkfOptions:
    """
    Options of BiasAugmentedEkf.
    """
    noise: RangeNoise
    nonnegative: bool
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        BiasAugmentedEkfOptions(**fields): the defaults, with any of the fields (noise, bias_prior_mean, bias_prior_std, bias_walk_std, iterations, nonnegative) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    def validate(self) -> None:
        """
        Raises ValueError naming the field that BiasAugmentedEkf would refuse; the fields are not checked when set.
        """
    @property
    def bias_prior_mean(self) -> float:
        ...
    @bias_prior_mean.setter
    def bias_prior_mean(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def bias_prior_std(self) -> float:
        ...
    @bias_prior_std.setter
    def bias_prior_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def bias_walk_std(self) -> float:
        ...
    @bias_walk_std.setter
    def bias_walk_std(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def iterations(self) -> int:
        ...
    @iterations.setter
    def iterations(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class BiasAugmentedEkf:
    """
    Iterated NLOS EKF (Najar & Vidal 2003, Ke & Wu Sec. 1): state [x, y, vx, vy, b_1..b_M], iterated EKF update.
    """
    def __copy__(self) -> BiasAugmentedEkf:
        ...
    def __deepcopy__(self, memo: dict) -> BiasAugmentedEkf:
        """
        An independent filter in the same state.
        """
    def __init__(self, motion: nlosloc._core.models.ConstantVelocity2, anchors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], options: BiasAugmentedEkfOptions = ..., t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def predict(self) -> None:
        ...
    def set_augmented_belief(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Replaces the whole belief, biases included: mean (4 + M,) [x, y, vx, vy, b_1..b_M] and cov (4 + M, 4 + M), symmetric positive definite, and the time when t is given. With mean, cov and time, the filter's whole state (what pickling stores).
        """
    def set_belief(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Sets the kinematic belief and, when t is given, the time; resets the biases to the prior.
        """
    def step(self, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> nlosloc._core.filters.StepResult:
        ...
    def update(self, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> nlosloc._core.filters.StepResult:
        ...
    @property
    def anchors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (M, 2).
        """
    @property
    def bias(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def cov(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Covariance (4 + M, 4 + M) (a copy).
        """
    @property
    def kinematic_mean(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def mean(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        [x, y, vx, vy, b_1..b_M] (a copy).
        """
    @property
    def motion(self) -> nlosloc._core.models.ConstantVelocity2:
        """
        The motion model (a copy).
        """
    @property
    def num_anchors(self) -> int:
        ...
    @property
    def options(self) -> BiasAugmentedEkfOptions:
        """
        The settings (a copy).
        """
    @property
    def state_dim(self) -> int:
        ...
    @property
    def time(self) -> float:
        ...
def make_box_qp(n: typing.SupportsInt | typing.SupportsIndex, settings: BoxQpSettings = ..., solver: str = 'default') -> BoxQp:
    """
    A BoxQp of n variables: solver 'default' (make_box_qp: proxsuite when built with it, else 'enumeration'), 'enumeration' (exact KKT search over the active sets, n <= 8, no allocation in solve; on a singular H it returns a vertex of the optimal set), 'proxsuite' (dense QP) or 'failing' (never solves).
    """
def reference_point(anchors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], hint: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"] | None = None) -> ReferencePoint:
    """
    Centre of the feasible region of the range discs (Ke & Wu Sec. 3): mean of the region's vertices; without vertices, `hint` if given, else the least-squares range fit. anchors (M, 2) finite, M >= 2; z (M,) finite ranges >= 0; else ValueError naming the argument.
    """
FLAG_BOUNDS_CLAMPED: int = 2
FLAG_DEGENERATE_GEOMETRY: int = 8
FLAG_MISSING_ROWS: int = 16
FLAG_QP_FAILED: int = 4
FLAG_REFERENCE_FALLBACK: int = 1
FLAG_UPDATE_REJECTED: int = 32
have_default_box_qp: bool = True
have_proxsuite_box_qp: bool = True
