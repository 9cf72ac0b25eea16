"""
Per-epoch solvers and baselines: MLE-LOS, CHEN, CONG, URR.
"""
from __future__ import annotations
import collections.abc
import nlosloc._core.models
import nlosloc._core.noise
import numpy
import numpy.typing
import typing
__all__: list[str] = ['Chen', 'ChenOptions', 'Cong', 'CongOptions', 'Fix', 'GaussNewtonOptions', 'LosSolver', 'MleLos', 'RowNoise', 'Urruela', 'UrruelaOptions', 'mask_count', 'subsets_at_least']
class RowNoise:
    """
    Noise model of one row in a fix: Gaussian or split (asymmetric) normal.
    """
    @staticmethod
    def gaussian(mean: typing.SupportsFloat | typing.SupportsIndex, std: typing.SupportsFloat | typing.SupportsIndex) -> RowNoise:
        """
        Gaussian N(mean, std^2): mean finite, std finite > 0.
        """
    @staticmethod
    def split(dist: nlosloc._core.noise.AsymmetricNormal) -> RowNoise:
        """
        From a noise.AsymmetricNormal (Cong & Zhuang 2005).
        """
    def __init__(self, center: typing.SupportsFloat | typing.SupportsIndex, sigma_left: typing.SupportsFloat | typing.SupportsIndex, sigma_right: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        center finite; sigma_left, sigma_right finite > 0 (ValueError naming the field otherwise).
        """
    def __repr__(self) -> str:
        ...
    def log_pdf(self, r: typing.SupportsFloat | typing.SupportsIndex) -> float:
        """
        log density of the residual r.
        """
    def normalized(self, r: typing.SupportsFloat | typing.SupportsIndex) -> float:
        """
        Normalised residual (r - center) / sigma, with sigma_left below the center, sigma_right above.
        """
    def valid(self) -> bool:
        """
        True when center is finite and both sigmas are finite > 0.
        """
    @property
    def center(self) -> float:
        """
        Mean (Gaussian) or mode (split normal) of the noise; finite.
        """
    @center.setter
    def center(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma_left(self) -> float:
        """
        Standard deviation left of the center; finite > 0.
        """
    @sigma_left.setter
    def sigma_left(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sigma_right(self) -> float:
        """
        Standard deviation right of the center; finite > 0.
        """
    @sigma_right.setter
    def sigma_right(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class GaussNewtonOptions:
    """
    Options of the Gauss-Newton / Levenberg-Marquardt fix.
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        GaussNewtonOptions(**fields): the defaults, with any of the fields (max_iterations, step_tolerance, initial_damping, max_damping) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def initial_damping(self) -> float:
        ...
    @initial_damping.setter
    def initial_damping(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_damping(self) -> float:
        ...
    @max_damping.setter
    def max_damping(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_iterations(self) -> int:
        ...
    @max_iterations.setter
    def max_iterations(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def step_tolerance(self) -> float:
        ...
    @step_tolerance.setter
    def step_tolerance(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class Fix:
    """
    Result of one Gauss-Newton fix.
    """
    def __repr__(self) -> str:
        ...
    @property
    def converged(self) -> bool:
        ...
    @property
    def cost(self) -> float:
        """
        Sum of squared normalised residuals.
        """
    @property
    def iterations(self) -> int:
        ...
    @property
    def rows(self) -> int:
        ...
    @property
    def theta(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Position (D) then clock bias.
        """
class LosSolver:
    """
    Per-epoch damped Gauss-Newton fix of position (and clock bias for RTOA rows) on a MeasurementStack (the MLE-LOS of Huerta Sec. VI-A and the inner solver of the baselines).
    """
    def __init__(self, measurements: nlosloc._core.models.MeasurementStack, options: GaussNewtonOptions = ...) -> None:
        ...
    def cost(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], use: collections.abc.Sequence[bool] | None = None, noise: collections.abc.Sequence[RowNoise] | None = None) -> float:
        """
        Sum of squared normalised residuals ((r_i - c_i) / s_i)^2 over the rows flagged in `use` (default all; NaN rows skipped) with per-row RowNoise `noise` (default LOS).
        """
    def linear_start(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], use: collections.abc.Sequence[bool] | None = None) -> typing.Any:
        """
        Closed-form linear LS start of the TOA/RTOA rows, or None when too few rows.
        """
    def residuals(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], theta: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Residuals y - g(theta) of every row (angle rows wrapped); y (rows,), theta (unknowns,).
        """
    def rows_of(self, mask: typing.SupportsInt | typing.SupportsIndex) -> list[bool]:
        """
        Row flags of the rows whose anchor (both for TDOA) is in the bit mask `mask`.
        """
    def solve(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], theta0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], use: collections.abc.Sequence[bool] | None = None, noise: collections.abc.Sequence[RowNoise] | None = None) -> Fix:
        """
        Fix from the rows flagged in `use` (default all) with per-row RowNoise `noise` (default LOS).
        """
    def solve_los(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], theta0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> Fix:
        """
        Fix from every row with the LOS Gaussian noise (MLE-LOS): solve(y, theta0) with the defaults.
        """
    def to_state(self, theta: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        The full state vector of the stack's layout (zeros but position and clock bias) of a fix theta.
        """
    @property
    def has_clock(self) -> bool:
        """
        True when the clock bias is an unknown.
        """
    @property
    def los_noise(self) -> list[RowNoise]:
        """
        The LOS Gaussian RowNoise of every row.
        """
    @property
    def measurements(self) -> nlosloc._core.models.MeasurementStack:
        """
        The measurement stack (a copy).
        """
    @property
    def options(self) -> GaussNewtonOptions:
        """
        A copy of the GaussNewtonOptions it was built with.
        """
    @property
    def space_dim(self) -> int:
        """
        Space dimension D.
        """
    @property
    def unknowns(self) -> int:
        """
        D, plus 1 with RTOA rows.
        """
class ChenOptions:
    """
    Options of Chen.
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        ChenOptions(**fields): the defaults, with any of the fields (min_size, reject_fraction, residual_floor) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def min_size(self) -> int:
        ...
    @min_size.setter
    def min_size(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def reject_fraction(self) -> float:
        ...
    @reject_fraction.setter
    def reject_fraction(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def residual_floor(self) -> float:
        ...
    @residual_floor.setter
    def residual_floor(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class CongOptions:
    """
    Options of Cong.
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        CongOptions(**fields): the defaults, with any of the fields (confidence, negative_sigmas, min_los, min_rows, fit_samples, fit_seed) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def confidence(self) -> float:
        ...
    @confidence.setter
    def confidence(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def fit_samples(self) -> int:
        ...
    @fit_samples.setter
    def fit_samples(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def fit_seed(self) -> int:
        ...
    @fit_seed.setter
    def fit_seed(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def min_los(self) -> int:
        ...
    @min_los.setter
    def min_los(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def min_rows(self) -> int:
        ...
    @min_rows.setter
    def min_rows(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def negative_sigmas(self) -> float:
        ...
    @negative_sigmas.setter
    def negative_sigmas(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class UrruelaOptions:
    """
    Options of Urruela.
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        UrruelaOptions(**fields): the defaults, with any of the fields (p_nlos, p_ln, p_nl, nlos_span) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def nlos_span(self) -> float:
        ...
    @nlos_span.setter
    def nlos_span(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def p_ln(self) -> float:
        ...
    @p_ln.setter
    def p_ln(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def p_nl(self) -> float:
        ...
    @p_nl.setter
    def p_nl(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def p_nlos(self) -> float:
        ...
    @p_nlos.setter
    def p_nlos(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class MleLos:
    """
    MLE-LOS (Huerta Sec. VI-A): per-epoch ML fix with every anchor assumed LOS.
    """
    def __init__(self, measurements: nlosloc._core.models.MeasurementStack, options: GaussNewtonOptions = ...) -> None:
        ...
    def reset(self, start: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        Sets the start of every fix: position (D) then clock bias (RTOA stacks); forgets warm starts.
        """
    def solve(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> dict:
        """
        Fix of one epoch y (rows of the stack, NaN = missing).
        
        Returns
        -------
        dict
            theta (position then clock bias), valid, cost, sight (0 LOS / 1 NLOS per anchor, zeros when the method does not classify), fixes (Gauss-Newton solves).
        """
    @property
    def classifies_sight(self) -> bool:
        """
        True when solve() decides the sight.
        """
    @property
    def gauss_newton(self) -> GaussNewtonOptions:
        """
        A copy of the GaussNewtonOptions of its solver.
        """
    @property
    def options(self) -> GaussNewtonOptions:
        """
        A copy of the options it was built with.
        """
    @property
    def sight(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        Sight decision of the last epoch (B).
        """
    @property
    def solver(self) -> LosSolver:
        """
        A copy of its LosSolver (the per-epoch Gauss-Newton fix on its measurement stack).
        """
    @property
    def unknowns(self) -> int:
        """
        D, plus 1 with RTOA rows.
        """
class Chen:
    """
    CHEN: Chen 1999 residual weighting over anchor combinations, 50% of the combinations with the largest normalised residual rejected (Huerta Sec. VI-B).
    """
    def __init__(self, measurements: nlosloc._core.models.MeasurementStack, options: ChenOptions = ..., gauss_newton: GaussNewtonOptions = ...) -> None:
        ...
    def reset(self, start: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        Sets the start of every fix: position (D) then clock bias (RTOA stacks); forgets warm starts.
        """
    def solve(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> dict:
        """
        Fix of one epoch y (rows of the stack, NaN = missing).
        
        Returns
        -------
        dict
            theta (position then clock bias), valid, cost, sight (0 LOS / 1 NLOS per anchor, zeros when the method does not classify), fixes (Gauss-Newton solves).
        """
    @property
    def classifies_sight(self) -> bool:
        """
        True when solve() decides the sight.
        """
    @property
    def combinations(self) -> list[int]:
        """
        Anchor bit masks of the combinations.
        """
    @property
    def gauss_newton(self) -> GaussNewtonOptions:
        """
        A copy of the GaussNewtonOptions of its solver.
        """
    @property
    def options(self) -> ChenOptions:
        """
        A copy of the options it was built with.
        """
    @property
    def sight(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        Sight decision of the last epoch (B).
        """
    @property
    def solver(self) -> LosSolver:
        """
        A copy of its LosSolver (the per-epoch Gauss-Newton fix on its measurement stack).
        """
    @property
    def unknowns(self) -> int:
        """
        D, plus 1 with RTOA rows.
        """
class Cong:
    """
    CONG: Cong & Zhuang 2005 residual-test NLOS identification; with too few LOS anchors the smallest-residual rows under an asymmetric Gaussian fit of the NLOS noise.
    """
    def __init__(self, measurements: nlosloc._core.models.MeasurementStack, options: CongOptions = ..., gauss_newton: GaussNewtonOptions = ...) -> None:
        ...
    def reset(self, start: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        Sets the start of every fix: position (D) then clock bias (RTOA stacks); forgets warm starts.
        """
    def solve(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> dict:
        """
        Fix of one epoch y (rows of the stack, NaN = missing).
        
        Returns
        -------
        dict
            theta (position then clock bias), valid, cost, sight (0 LOS / 1 NLOS per anchor, zeros when the method does not classify), fixes (Gauss-Newton solves).
        """
    @property
    def classifies_sight(self) -> bool:
        """
        True when solve() decides the sight.
        """
    @property
    def enough_los(self) -> bool:
        """
        True when the last epoch found a LOS set.
        """
    @property
    def gauss_newton(self) -> GaussNewtonOptions:
        """
        A copy of the GaussNewtonOptions of its solver.
        """
    @property
    def nlos_noise(self) -> list[RowNoise]:
        """
        Fitted split normal of each row's NLOS noise.
        """
    @property
    def options(self) -> CongOptions:
        """
        A copy of the options it was built with.
        """
    @property
    def sight(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        Sight decision of the last epoch (B).
        """
    @property
    def solver(self) -> LosSolver:
        """
        A copy of its LosSolver (the per-epoch Gauss-Newton fix on its measurement stack).
        """
    @property
    def unknowns(self) -> int:
        """
        D, plus 1 with RTOA rows.
        """
class Urruela:
    """
    URR: Riba & Urruela ML detection of the LOS set with the Urruela-Morata-Riba trellis (Viterbi) search over time, on TDOA.
    """
    def __init__(self, measurements: nlosloc._core.models.MeasurementStack, options: UrruelaOptions = ..., gauss_newton: GaussNewtonOptions = ...) -> None:
        ...
    def reset(self, start: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        Sets the start of every fix: position (D) then clock bias (RTOA stacks); forgets warm starts.
        """
    def solve(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> dict:
        """
        Fix of one epoch y (rows of the stack, NaN = missing).
        
        Returns
        -------
        dict
            theta (position then clock bias), valid, cost, sight (0 LOS / 1 NLOS per anchor, zeros when the method does not classify), fixes (Gauss-Newton solves).
        """
    @property
    def classifies_sight(self) -> bool:
        """
        True when solve() decides the sight.
        """
    @property
    def gauss_newton(self) -> GaussNewtonOptions:
        """
        A copy of the GaussNewtonOptions of its solver.
        """
    @property
    def hypotheses(self) -> list[int]:
        """
        LOS anchor bit masks of the trellis states.
        """
    @property
    def options(self) -> UrruelaOptions:
        """
        A copy of the options it was built with.
        """
    @property
    def path_metrics(self) -> list[float]:
        """
        Viterbi metrics (minimum 0).
        """
    @property
    def sight(self) -> typing.Annotated[numpy.typing.NDArray[numpy.int32], "[m, 1]"]:
        """
        Sight decision of the last epoch (B).
        """
    @property
    def solver(self) -> LosSolver:
        """
        A copy of its LosSolver (the per-epoch Gauss-Newton fix on its measurement stack).
        """
    @property
    def unknowns(self) -> int:
        """
        D, plus 1 with RTOA rows.
        """
def mask_count(mask: typing.SupportsInt | typing.SupportsIndex) -> int:
    """
    Number of anchors in an anchor bit mask.
    """
def subsets_at_least(num_anchors: typing.SupportsInt | typing.SupportsIndex, min_size: typing.SupportsInt | typing.SupportsIndex) -> list[int]:
    """
    Every anchor bit mask over num_anchors (1..20) anchors with at least min_size anchors, larger sets first, then ascending mask value.
    """
