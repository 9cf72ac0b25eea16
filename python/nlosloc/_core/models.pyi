"""
Motion and measurement models (TOA, RTOA, TDOA, AOA, TWR).
"""
from __future__ import annotations
import collections.abc
import nlosloc._core.noise
import numpy
import numpy.typing
import typing
__all__: list[str] = ['ConstantVelocity2', 'ConstantVelocity3', 'ConstantVelocityClock2', 'ConstantVelocityClock3', 'MeasurementRow', 'MeasurementStack', 'RowKind', 'StateLayout', 'TwoWayClock', 'TwrParams', 'VelocityNoise']
class StateLayout:
    """
    Indices of the state pieces (-1 = absent).
    """
    def __init__(self, *args: typing.Any, **fields: typing.Any) -> None:
        """
        StateLayout(**fields): the defaults, with any of the fields (dim, space_dim, position, velocity, clock_bias, clock_drift, skew, offset) set by keyword.
        """
    def __repr__(self) -> str:
        ...
    @property
    def clock_bias(self) -> int:
        ...
    @clock_bias.setter
    def clock_bias(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def clock_drift(self) -> int:
        ...
    @clock_drift.setter
    def clock_drift(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def dim(self) -> int:
        ...
    @dim.setter
    def dim(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def offset(self) -> int:
        ...
    @offset.setter
    def offset(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def position(self) -> int:
        ...
    @position.setter
    def position(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def skew(self) -> int:
        ...
    @skew.setter
    def skew(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def space_dim(self) -> int:
        ...
    @space_dim.setter
    def space_dim(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def velocity(self) -> int:
        ...
    @velocity.setter
    def velocity(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class VelocityNoise:
    """
    Process-noise form of the constant-velocity model.
    
    Members:
    
      RandomWalk : Huerta eqs. (6)-(7)
    
      WhiteAcceleration : Ke and Wu eq. (16)
    """
    RandomWalk: typing.ClassVar[VelocityNoise]
    WhiteAcceleration: typing.ClassVar[VelocityNoise]
    __members__: typing.ClassVar[dict[str, VelocityNoise]]
    @typing.overload
    def __eq__(self, other: VelocityNoise) -> bool:
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
    def __ne__(self, other: VelocityNoise) -> bool:
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
class ConstantVelocity2:
    """
    Constant velocity in 2-D, state [p, v] (Huerta eqs. 6-7 random walk, Ke and Wu eq. 16 white acceleration).
    """
    dim: typing.ClassVar[int] = 4
    @staticmethod
    def layout() -> StateLayout:
        """
        Where position, velocity and clock sit in the state.
        """
    def __init__(self, dt: typing.SupportsFloat | typing.SupportsIndex, sigma2: typing.SupportsFloat | typing.SupportsIndex, noise: VelocityNoise = VelocityNoise.RandomWalk) -> None:
        """
        dt > 0 (s); sigma2 >= 0: velocity random-walk rate ((m/s)^2/s) or acceleration variance ((m/s^2)^2) depending on `noise`.
        """
    @property
    def F(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        Transition matrix, shape (n, n).
        """
    @property
    def Q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        Process-noise covariance, shape (n, n).
        """
    @property
    def dt(self) -> float:
        """
        Time step (s).
        """
    @property
    def noise(self) -> VelocityNoise:
        ...
    @property
    def sigma2(self) -> float:
        ...
class ConstantVelocity3:
    """
    Constant velocity in 3-D, state [p, v] (Huerta eqs. 6-7 random walk, Ke and Wu eq. 16 white acceleration).
    """
    dim: typing.ClassVar[int] = 6
    @staticmethod
    def layout() -> StateLayout:
        """
        Where position, velocity and clock sit in the state.
        """
    def __init__(self, dt: typing.SupportsFloat | typing.SupportsIndex, sigma2: typing.SupportsFloat | typing.SupportsIndex, noise: VelocityNoise = VelocityNoise.RandomWalk) -> None:
        """
        dt > 0 (s); sigma2 >= 0: velocity random-walk rate ((m/s)^2/s) or acceleration variance ((m/s^2)^2) depending on `noise`.
        """
    @property
    def F(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 6]"]:
        """
        Transition matrix, shape (n, n).
        """
    @property
    def Q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 6]"]:
        """
        Process-noise covariance, shape (n, n).
        """
    @property
    def dt(self) -> float:
        """
        Time step (s).
        """
    @property
    def noise(self) -> VelocityNoise:
        ...
    @property
    def sigma2(self) -> float:
        ...
class ConstantVelocityClock2:
    """
    Constant velocity plus clock bias (light-metres) and drift, state [p, tau, v, tau_dot] (Huerta eqs. 5-7).
    """
    dim: typing.ClassVar[int] = 6
    @staticmethod
    def layout() -> StateLayout:
        """
        Where position, velocity and clock sit in the state.
        """
    def __init__(self, dt: typing.SupportsFloat | typing.SupportsIndex, sigma_v2: typing.SupportsFloat | typing.SupportsIndex, sigma_tau2: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        dt > 0 (s); sigma_v2 >= 0 ((m/s)^2/s); sigma_tau2 >= 0 ((lm/s)^2/s).
        """
    @property
    def F(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 6]"]:
        """
        Transition matrix, shape (n, n).
        """
    @property
    def Q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 6]"]:
        """
        Process-noise covariance, shape (n, n).
        """
    @property
    def dt(self) -> float:
        """
        Time step (s).
        """
    @property
    def sigma_tau2(self) -> float:
        ...
    @property
    def sigma_v2(self) -> float:
        ...
class ConstantVelocityClock3:
    """
    Constant velocity plus clock bias (light-metres) and drift, state [p, tau, v, tau_dot] (Huerta eqs. 5-7).
    """
    dim: typing.ClassVar[int] = 8
    @staticmethod
    def layout() -> StateLayout:
        """
        Where position, velocity and clock sit in the state.
        """
    def __init__(self, dt: typing.SupportsFloat | typing.SupportsIndex, sigma_v2: typing.SupportsFloat | typing.SupportsIndex, sigma_tau2: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        dt > 0 (s); sigma_v2 >= 0 ((m/s)^2/s); sigma_tau2 >= 0 ((lm/s)^2/s).
        """
    @property
    def F(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[8, 8]"]:
        """
        Transition matrix, shape (n, n).
        """
    @property
    def Q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[8, 8]"]:
        """
        Process-noise covariance, shape (n, n).
        """
    @property
    def dt(self) -> float:
        """
        Time step (s).
        """
    @property
    def sigma_tau2(self) -> float:
        ...
    @property
    def sigma_v2(self) -> float:
        ...
class TwoWayClock:
    """
    Two-way-ranging clock and mobility model, state (omega, phi, vx, vy, x, y) (Grisales and Fierens eqs. 14-15).
    """
    dim: typing.ClassVar[int] = 6
    @staticmethod
    def layout() -> StateLayout:
        """
        Where position, velocity and clock sit in the state.
        """
    def __init__(self, h: typing.SupportsFloat | typing.SupportsIndex, sigma_omega: typing.SupportsFloat | typing.SupportsIndex, sigma_phi: typing.SupportsFloat | typing.SupportsIndex, sigma_v: typing.SupportsFloat | typing.SupportsIndex) -> None:
        """
        h > 0: period (s); step standard deviations of skew, offset (s), velocity (m/s).
        """
    @property
    def F(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 6]"]:
        """
        Transition matrix, shape (n, n).
        """
    @property
    def Q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[6, 6]"]:
        """
        Process-noise covariance, shape (n, n).
        """
    @property
    def dt(self) -> float:
        """
        Time step (s).
        """
    @property
    def sigma_omega(self) -> float:
        ...
    @property
    def sigma_phi(self) -> float:
        ...
    @property
    def sigma_v(self) -> float:
        ...
class RowKind:
    """
    Kind of a measurement row.
    
    Members:
    
      Toa
    
      Rtoa
    
      Tdoa
    
      Aoa
    
      AoaPhase
    
      TwrTau
    
      TwrT
    
      Linear
    """
    Aoa: typing.ClassVar[RowKind]
    AoaPhase: typing.ClassVar[RowKind]
    Linear: typing.ClassVar[RowKind]
    Rtoa: typing.ClassVar[RowKind]
    Tdoa: typing.ClassVar[RowKind]
    Toa: typing.ClassVar[RowKind]
    TwrT: typing.ClassVar[RowKind]
    TwrTau: typing.ClassVar[RowKind]
    __members__: typing.ClassVar[dict[str, RowKind]]
    @typing.overload
    def __eq__(self, other: RowKind) -> bool:
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
    def __ne__(self, other: RowKind) -> bool:
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
class MeasurementRow:
    """
    Description of one row of a MeasurementStack.
    """
    @property
    def anchor(self) -> int:
        ...
    @property
    def anchor2(self) -> int:
        ...
    @property
    def input(self) -> int:
        ...
    @property
    def inputs(self) -> int:
        ...
    @property
    def kind(self) -> RowKind:
        ...
    @property
    def linear(self) -> int:
        """
        Linear rows: index of the row's coefficients among the stack's linear rows; else -1.
        """
    @property
    def sector_center(self) -> float:
        ...
    @property
    def slot(self) -> int:
        ...
class TwrParams:
    """
    Parameters of a two-way-ranging pair (add_twr).
    """
    def __repr__(self) -> str:
        ...
    @property
    def delta_slot(self) -> float:
        """
        Delta (s).
        """
    @property
    def gamma(self) -> list[nlosloc._core.noise.Distribution | None]:
        """
        NLOS delay distribution per condition (None: no delay).
        """
    @property
    def reply_delay(self) -> float:
        """
        delta (s).
        """
    @property
    def sigma_m(self) -> float:
        """
        Time-stamping noise std (s).
        """
class MeasurementStack:
    """
    Stack of measurement rows y = g(x) + n(s), each tied to an anchor whose sight condition s selects the row's noise (Huerta Table I; Grisales eqs. 17-20). Build it once with the add_* methods.
    """
    def __init__(self, layout: StateLayout, anchors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], num_conditions: typing.SupportsInt | typing.SupportsIndex = 2) -> None:
        """
        layout: from the motion model (e.g. ConstantVelocity2.layout()); anchors: (B, D) positions in m; num_conditions: sight conditions per anchor (0 = LOS).
        """
    def add_aoa(self, anchor: typing.SupportsInt | typing.SupportsIndex, noise: collections.abc.Sequence[nlosloc._core.noise.Distribution]) -> MeasurementStack:
        """
        Geometric AOA row (rad), residuals wrapped.
        """
    def add_aoa_phase(self, anchor: typing.SupportsInt | typing.SupportsIndex, sector_center: typing.SupportsFloat | typing.SupportsIndex, noise: collections.abc.Sequence[nlosloc._core.noise.Distribution]) -> MeasurementStack:
        """
        ULA phase row psi = pi sin(theta - sector_center) (scenario H1).
        """
    def add_linear(self, h: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], anchor: typing.SupportsInt | typing.SupportsIndex, noise: collections.abc.Sequence[nlosloc._core.noise.Distribution]) -> MeasurementStack:
        """
        Linear row h^T x.
        """
    def add_rtoa(self, anchor: typing.SupportsInt | typing.SupportsIndex, noise: collections.abc.Sequence[nlosloc._core.noise.Distribution]) -> MeasurementStack:
        """
        RTOA (pseudorange) row, needs a clock-bias state.
        """
    def add_tdoa(self, anchor_a: typing.SupportsInt | typing.SupportsIndex, anchor_b: typing.SupportsInt | typing.SupportsIndex, noise_a: collections.abc.Sequence[nlosloc._core.noise.Distribution], noise_b: collections.abc.Sequence[nlosloc._core.noise.Distribution]) -> MeasurementStack:
        """
        TDOA row ||p - q_a|| - ||p - q_b|| with noise n_a - n_b.
        """
    def add_toa(self, anchor: typing.SupportsInt | typing.SupportsIndex, noise: collections.abc.Sequence[nlosloc._core.noise.Distribution]) -> MeasurementStack:
        """
        TOA row; `noise`: one distribution per condition.
        """
    def add_twr(self, anchor: typing.SupportsInt | typing.SupportsIndex, slot: typing.SupportsInt | typing.SupportsIndex, delta_slot: typing.SupportsFloat | typing.SupportsIndex, reply_delay: typing.SupportsFloat | typing.SupportsIndex, sigma_m: typing.SupportsFloat | typing.SupportsIndex, gamma: collections.abc.Sequence[nlosloc._core.noise.Distribution | None]) -> MeasurementStack:
        """
        Two-way-ranging pair (tau, T) of Grisales eqs. (17)-(20); gamma[z]: NLOS delay distribution of condition z, None for no delay.
        """
    def check_sight(self, sight: typing.Any) -> None:
        """
        Raises ValueError unless sight is (B,) integers in [0, num_conditions): the check every filter applies to a sight vector.
        """
    def is_angle(self, i: typing.SupportsInt | typing.SupportsIndex) -> bool:
        ...
    def jacobian(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Analytic Jacobian dg/dx, shape (rows, n).
        """
    def linear_h(self, i: int) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        h of linear row i (y = h^T x + n), a copy.
        """
    def noise(self, i: typing.SupportsInt | typing.SupportsIndex, condition: typing.SupportsInt | typing.SupportsIndex) -> nlosloc._core.noise.Distribution:
        """
        Noise distribution of row i under a condition (the first anchor's for TDOA); ValueError for a two-way-ranging row (see twr_params).
        """
    def noise_b(self, i: typing.SupportsInt | typing.SupportsIndex, condition: typing.SupportsInt | typing.SupportsIndex) -> nlosloc._core.noise.Distribution:
        """
        Noise of the second anchor (n_b of n_a - n_b) of TDOA row i.
        """
    def noise_moments(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], sight: typing.Any) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]]:
        """
        (mean, cov) of the noise under `sight` at x.
        """
    def predict(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Noise-free prediction g(x), shape (rows,).
        """
    def predict_augmented(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], t: typing.SupportsFloat | typing.SupportsIndex, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], sight: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        g(x) plus noise built from standard normals u (noise_dim,) through each quantile map.
        """
    def predict_columns(self, X: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        g at every column of X (n, K): shape (rows, K), as predict() per column (the UKF's sigma-point path, row by row).
        """
    def residual(self, a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        a - b with angle rows wrapped to (-pi, pi].
        """
    def row(self, i: typing.SupportsInt | typing.SupportsIndex) -> MeasurementRow:
        ...
    def twr_params(self, i: typing.SupportsInt | typing.SupportsIndex) -> TwrParams:
        """
        Parameters of two-way-ranging row i (either row of its pair), as given to add_twr.
        """
    @property
    def anchors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def has_angles(self) -> bool:
        """
        True when any row is an angle (AOA).
        """
    @property
    def layout(self) -> StateLayout:
        ...
    @property
    def noise_dim(self) -> int:
        ...
    @property
    def num_anchors(self) -> int:
        ...
    @property
    def num_conditions(self) -> int:
        ...
    @property
    def rows(self) -> int:
        ...
