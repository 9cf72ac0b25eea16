"""
Estimators: KF, EKF, UKF (the IUKF and the particle filters: nlosloc.rbpf).
"""
from __future__ import annotations
import nlosloc._core.core
import nlosloc._core.models
import numpy
import numpy.typing
import typing
__all__: list[str] = ['Ekf', 'Kf', 'NoiseForm', 'StepResult', 'Ukf', 'UkfAugmented']
class NoiseForm:
    """
    How a sigma-point filter treats the measurement noise.
    
    Members:
    
      Additive : y = g(x) + n with n's exact mean and covariance (Ukf).
    
      Augmented : Noise inside the sigma points through each row's quantile (Huerta Table III, UkfAugmented).
    """
    Additive: typing.ClassVar[NoiseForm]
    Augmented: typing.ClassVar[NoiseForm]
    __members__: typing.ClassVar[dict[str, NoiseForm]]
    @typing.overload
    def __eq__(self, other: NoiseForm) -> bool:
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
    def __ne__(self, other: NoiseForm) -> bool:
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
class StepResult:
    """
    What one update reports.
    """
    def __repr__(self) -> str:
        ...
    @property
    def jitter(self) -> float:
        """
        Diagonal added by the Cholesky fallback, if any.
        """
    @property
    def log_likelihood(self) -> float:
        """
        log p(y_t | y_1:t-1, s), Gaussian predictive over the rows used (Huerta (III.2)).
        """
    @property
    def rows_used(self) -> int:
        """
        Rows that were not NaN.
        """
    @property
    def status(self) -> nlosloc._core.core.CholeskyStatus:
        """
        Worst Cholesky outcome of the step.
        """
class Kf:
    """
    Linear Kalman filter y = H x + n, n ~ N(0, R).
    """
    def __init__(self, motion: typing.Any, H: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], R: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        motion: any motion model; H (m, n); R (m, m) SPD; initial belief N(mean, cov).
        """
    def belief(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        The belief as a tuple (mean (n,), cov (n, n)).
        """
    def predict(self) -> None:
        """
        Prediction x = F x, P = F P F^T + Q; time advances by dt.
        """
    def set_belief(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Replaces the belief (validated: finite mean, symmetric positive definite cov).
        """
    def step(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> StepResult:
        """
        predict() then update(y).
        """
    def update(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> StepResult:
        """
        Update with y (m,), NaN = missing.
        """
    @property
    def H(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (m, n).
        """
    @property
    def R(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (m, m).
        """
    @property
    def cov(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Posterior covariance, shape (n, n).
        """
    @property
    def dim(self) -> int:
        ...
    @property
    def mean(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Posterior mean, shape (n,).
        """
    @property
    def motion(self) -> typing.Any:
        """
        The motion model (a copy).
        """
    @property
    def rows(self) -> int:
        ...
    @property
    def time(self) -> float:
        """
        Time of the belief (s).
        """
class Ekf:
    """
    Extended Kalman filter over a MeasurementStack (noise moments per sight).
    """
    def __init__(self, motion: typing.Any, measurements: nlosloc._core.models.MeasurementStack, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def belief(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        The belief as a tuple (mean (n,), cov (n, n)).
        """
    def predict(self) -> None:
        """
        Prediction x = F x, P = F P F^T + Q; time advances by dt.
        """
    def run(self, Y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], sight: typing.Any = None) -> dict:
        """
        Runs step() over the rows of Y (T, m) in one call (GIL released). sight: None, (B,) or (T, B). Returns a dict with mean (T, n), cov (T, n, n), log_likelihood (T,), rows_used (T,).
        """
    def set_belief(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Replaces the belief (validated: finite mean, symmetric positive definite cov).
        """
    def step(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], sight: typing.Any = None) -> StepResult:
        """
        predict() then update(y, sight).
        """
    def update(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], sight: typing.Any = None) -> StepResult:
        """
        Update with y (m,) (NaN = missing row) and optional sight (B,) ints (default all LOS). Returns a StepResult with the predictive log-likelihood.
        """
    @property
    def cov(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Posterior covariance, shape (n, n).
        """
    @property
    def dim(self) -> int:
        ...
    @property
    def mean(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Posterior mean, shape (n,).
        """
    @property
    def measurements(self) -> nlosloc._core.models.MeasurementStack:
        ...
    @property
    def motion(self) -> typing.Any:
        """
        The motion model (a copy).
        """
    @property
    def time(self) -> float:
        """
        Time of the belief (s).
        """
class Ukf:
    """
    UKF with additive measurement noise (exact linear prediction; sigma points redrawn from the predicted belief for the update).
    """
    def __init__(self, motion: typing.Any, measurements: nlosloc._core.models.MeasurementStack, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], scheme: nlosloc._core.core.SigmaScheme = ..., t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def belief(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        The belief as a tuple (mean (n,), cov (n, n)).
        """
    def predict(self) -> None:
        """
        Prediction x = F x, P = F P F^T + Q; time advances by dt.
        """
    def run(self, Y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], sight: typing.Any = None) -> dict:
        """
        Runs step() over the rows of Y (T, m) in one call (GIL released). sight: None, (B,) or (T, B). Returns a dict with mean (T, n), cov (T, n, n), log_likelihood (T,), rows_used (T,).
        """
    def set_belief(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Replaces the belief (validated: finite mean, symmetric positive definite cov).
        """
    def step(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], sight: typing.Any = None) -> StepResult:
        """
        predict() then update(y, sight).
        """
    def update(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], sight: typing.Any = None) -> StepResult:
        """
        Update with y (m,) (NaN = missing row) and optional sight (B,) ints (default all LOS). Returns a StepResult with the predictive log-likelihood.
        """
    @property
    def cov(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Posterior covariance, shape (n, n).
        """
    @property
    def dim(self) -> int:
        ...
    @property
    def mean(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Posterior mean, shape (n,).
        """
    @property
    def measurements(self) -> nlosloc._core.models.MeasurementStack:
        ...
    @property
    def motion(self) -> typing.Any:
        """
        The motion model (a copy).
        """
    @property
    def scheme(self) -> nlosloc._core.core.SigmaScheme:
        """
        The sigma-point scheme (a copy).
        """
    @property
    def time(self) -> float:
        """
        Time of the belief (s).
        """
    @property
    def weights(self) -> nlosloc._core.core.SigmaWeights:
        """
        The sigma-point weights of the update (a copy).
        """
class UkfAugmented:
    """
    UKF with the measurement noise in the sigma points through each distribution's quantile map (Huerta Sec. V-A; Grisales eq. 29).
    """
    def __init__(self, motion: typing.Any, measurements: nlosloc._core.models.MeasurementStack, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], scheme: nlosloc._core.core.SigmaScheme = ..., t0: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    def belief(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        The belief as a tuple (mean (n,), cov (n, n)).
        """
    def predict(self) -> None:
        """
        Prediction x = F x, P = F P F^T + Q; time advances by dt.
        """
    def run(self, Y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], sight: typing.Any = None) -> dict:
        """
        Runs step() over the rows of Y (T, m) in one call (GIL released). sight: None, (B,) or (T, B). Returns a dict with mean (T, n), cov (T, n, n), log_likelihood (T,), rows_used (T,).
        """
    def set_belief(self, mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Replaces the belief (validated: finite mean, symmetric positive definite cov).
        """
    def step(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], sight: typing.Any = None) -> StepResult:
        """
        predict() then update(y, sight).
        """
    def update(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], sight: typing.Any = None) -> StepResult:
        """
        Update with y (m,) (NaN = missing row) and optional sight (B,) ints (default all LOS). Returns a StepResult with the predictive log-likelihood.
        """
    @property
    def augmented_dim(self) -> int:
        """
        n + q: the state plus the measurement noise inputs in the sigma points (Huerta eq. 49).
        """
    @property
    def cov(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Posterior covariance, shape (n, n).
        """
    @property
    def dim(self) -> int:
        ...
    @property
    def mean(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Posterior mean, shape (n,).
        """
    @property
    def measurements(self) -> nlosloc._core.models.MeasurementStack:
        ...
    @property
    def motion(self) -> typing.Any:
        """
        The motion model (a copy).
        """
    @property
    def scheme(self) -> nlosloc._core.core.SigmaScheme:
        """
        The sigma-point scheme (a copy).
        """
    @property
    def time(self) -> float:
        """
        Time of the belief (s).
        """
    @property
    def weights(self) -> nlosloc._core.core.SigmaWeights:
        """
        The sigma-point weights of the update (a copy).
        """
