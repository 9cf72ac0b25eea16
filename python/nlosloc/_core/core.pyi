"""
Core types: Gaussian beliefs, sigma points, robust Cholesky, Rng.
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
__all__: list[str] = ['BatchRng', 'CholeskyStatus', 'NumericalError', 'Rng', 'SPEED_OF_LIGHT', 'SigmaScheme', 'SigmaWeights', 'are_log_weights', 'gaussian_log_pdf_chol', 'is_spd', 'is_spsd', 'log_normalize', 'log_sum_exp', 'robust_cholesky', 'sigma_points', 'wrap_angle']
class NumericalError(RuntimeError):
    """
    Raised when a step cannot be completed numerically (a covariance that is not positive definite even with the Cholesky fallback). The filter keeps the belief it had before the call.
    """
class Rng:
    """
    Seeded xoshiro256++ generator; every random draw of nlosloc goes through one.
    """
    STATE_WORDS: typing.ClassVar[int] = 6
    def __call__(self) -> int:
        """
        Next raw 64-bit output.
        """
    def __getstate__(self) -> tuple[list[int]]:
        ...
    def __init__(self, seed: int = 0, stream: int = 0) -> None:
        """
        Generator for `seed`; `stream` selects an independent sequence (e.g. a Monte Carlo run).
        """
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def below(self, n: typing.SupportsInt | typing.SupportsIndex) -> int:
        """
        Uniform integer in [0, n), n >= 1.
        """
    def jump(self) -> None:
        """
        Advances the generator by 2^128 draws (xoshiro256 jump): non-overlapping subsequences.
        """
    @typing.overload
    def normal(self) -> float:
        """
        Standard normal draw.
        """
    @typing.overload
    def normal(self, mu: typing.SupportsFloat | typing.SupportsIndex, sigma: typing.SupportsFloat | typing.SupportsIndex) -> float:
        """
        Normal draw with mean mu and standard deviation sigma.
        """
    def normals(self, n: typing.SupportsInt | typing.SupportsIndex) -> numpy.typing.NDArray[numpy.float64]:
        """
        Array of `n` standard normal draws, shape (n,).
        """
    def reseed(self, seed: int, stream: int = 0) -> None:
        """
        Restarts the generator as Rng(seed, stream) would (in place, e.g. the rng a Monte Carlo estimator is given).
        """
    def restore_state(self, words: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> None:
        """
        Sets the state from save_state() words (checked first: ValueError, nothing changed).
        """
    def save_state(self) -> list[int]:
        """
        The whole state as a list of 64-bit words: restore_state() of it continues the same sequence.
        """
    def state(self) -> typing.Annotated[list[int], "FixedSize(4)"]:
        """
        The four 64-bit words of the xoshiro256 state.
        """
    def uniform(self) -> float:
        """
        Uniform draw in the open interval (0, 1).
        """
class BatchRng:
    """
    Bulk generator of the particle filter: 4 xoshiro256++ lanes in lockstep, lane l being the parent Rng jumped l + 1 times (the parent is not advanced).
    """
    BUFFER: typing.ClassVar[int] = 64
    LANES: typing.ClassVar[int] = 4
    STATE_WORDS: typing.ClassVar[int] = 81
    def __call__(self) -> int:
        """
        Next raw 64-bit word.
        """
    def __getstate__(self) -> tuple[list[int]]:
        ...
    def __init__(self, parent: Rng = ...) -> None:
        """
        Lanes derived from `parent` by jumps (default Rng(): seed 0, stream 0, as C++ BatchRng()).
        """
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def bits(self, n_quads: typing.SupportsInt | typing.SupportsIndex) -> numpy.typing.NDArray[numpy.uint64]:
        """
        4 * n_quads raw words, shape (4 n_quads,): word 4 j + l is lane l's j-th output.
        """
    def normals(self, n: typing.SupportsInt | typing.SupportsIndex) -> numpy.typing.NDArray[numpy.float64]:
        """
        n standard normal variates (ziggurat, Marsaglia and Tsang 2000); shape (n,).
        """
    def restore_state(self, words: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> None:
        """
        Sets the state from save_state() words (checked first: ValueError, nothing changed).
        """
    def save_state(self) -> list[int]:
        """
        The whole state as a list of 64-bit words: restore_state() of it continues the same sequence.
        """
    def uniform(self) -> float:
        """
        One uniform in (0, 1) with 53 random bits.
        """
    def uniforms(self, n: typing.SupportsInt | typing.SupportsIndex) -> numpy.typing.NDArray[numpy.float64]:
        """
        n uniforms in (0, 1) with 52 random bits each, n a multiple of 4; shape (n,).
        """
    def use_avx2(self, on: bool) -> None:
        """
        Refill on 256-bit AVX2 registers from now on (on, and the CPU has AVX2; x86-64 GCC/Clang builds) or on SSE2 / scalar code (the default). The words are the same either way; not part of save_state().
        """
    @property
    def uses_avx2(self) -> bool:
        """
        Whether refills run on AVX2 registers.
        """
class SigmaWeights:
    """
    Weights of a 2n+1 sigma-point set.
    """
    def __repr__(self) -> str:
        ...
    @property
    def gamma(self) -> float:
        """
        Spread: points are mean +- gamma * L[:, i].
        """
    @property
    def wc0(self) -> float:
        """
        Covariance weight of the centre point.
        """
    @property
    def wi(self) -> float:
        """
        Weight of each of the 2n outer points.
        """
    @property
    def wm0(self) -> float:
        """
        Mean weight of the centre point.
        """
class SigmaScheme:
    """
    Sigma-point rule of the unscented transform.
    """
    class Kind:
        """
        Members:
        
          Scaled
        
          Julier
        
          Cubature
        
          Huerta
        """
        Cubature: typing.ClassVar[SigmaScheme.Kind]
        Huerta: typing.ClassVar[SigmaScheme.Kind]
        Julier: typing.ClassVar[SigmaScheme.Kind]
        Scaled: typing.ClassVar[SigmaScheme.Kind]
        __members__: typing.ClassVar[dict[str, SigmaScheme.Kind]]
        @typing.overload
        def __eq__(self, other: SigmaScheme.Kind) -> bool:
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
        def __ne__(self, other: SigmaScheme.Kind) -> bool:
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
    @staticmethod
    def cubature() -> SigmaScheme:
        """
        Spherical-radial cubature rule (2n points).
        """
    @staticmethod
    def huerta(alpha: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> SigmaScheme:
        """
        Huerta et al. 2009 eqs. (49)-(52) (scaled rule with kappa = 0, beta = 2).
        """
    @staticmethod
    def julier(kappa: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> SigmaScheme:
        """
        Julier and Uhlmann's UT.
        """
    @staticmethod
    def scaled(alpha: typing.SupportsFloat | typing.SupportsIndex = 0.001, beta: typing.SupportsFloat | typing.SupportsIndex = 2.0, kappa: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> SigmaScheme:
        """
        Scaled UT of Wan and van der Merwe (FilterPy's MerweScaledSigmaPoints); alpha in (0, 1].
        """
    def __eq__(self, arg0: typing.Any) -> typing.Any:
        ...
    def __hash__(self) -> int:
        ...
    def __init__(self, kind: SigmaScheme.Kind = ..., alpha: typing.SupportsFloat | typing.SupportsIndex = 1.0, beta: typing.SupportsFloat | typing.SupportsIndex = 2.0, kappa: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        """
        A scheme from its four fields, as the C++ aggregate (checked when weights() or validate() are called; the factories below give each kind's usual parameters).
        """
    def __repr__(self) -> str:
        ...
    def validate(self, n: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        Raises ValueError (naming the parameter) unless the scheme gives valid weights for dimension n.
        """
    def weights(self, n: typing.SupportsInt | typing.SupportsIndex) -> SigmaWeights:
        """
        Weights for an n-dimensional variable.
        """
    @property
    def alpha(self) -> float:
        ...
    @property
    def beta(self) -> float:
        ...
    @property
    def kappa(self) -> float:
        ...
    @property
    def kind(self) -> SigmaScheme.Kind:
        ...
class CholeskyStatus:
    """
    Outcome of a factorisation (see robust_cholesky).
    
    Members:
    
      Ok
    
      Jittered
    
      Failed
    """
    Failed: typing.ClassVar[CholeskyStatus]
    Jittered: typing.ClassVar[CholeskyStatus]
    Ok: typing.ClassVar[CholeskyStatus]
    __members__: typing.ClassVar[dict[str, CholeskyStatus]]
    @typing.overload
    def __eq__(self, other: CholeskyStatus) -> bool:
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
    def __ne__(self, other: CholeskyStatus) -> bool:
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
def are_log_weights(v: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> bool:
    """
    True when every entry is a valid log weight: finite or -inf (a ruled-out particle), never NaN or +inf.
    """
def gaussian_log_pdf_chol(L: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> float:
    """
    log N(x; 0, S) from the lower Cholesky factor L of S (m, m) and x (m,).
    """
def is_spd(A: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], rel_tol: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> bool:
    """
    True when A is square, finite, symmetric to rel_tol (relative to its largest entry) and positive definite: the check set_belief applies to a covariance.
    """
def is_spsd(A: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], rel_tol: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> bool:
    """
    True when A is square, finite, symmetric to rel_tol (relative to its largest entry) and positive semi-definite (LDLT pivots >= -rel_tol max|A|): the check a particle set's covariance passes.
    """
def log_normalize(v: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"], float]:
    """
    Log weights normalised so that sum(exp) = 1, and the normaliser log_sum_exp(v): a tuple (v - z, z) (v unchanged when z is not finite).
    """
def log_sum_exp(v: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> float:
    """
    log(sum(exp(v))) computed stably; -inf for empty input.
    """
def robust_cholesky(A: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], CholeskyStatus, float]:
    """
    Lower Cholesky factor with the documented fallback: returns (L, status, jitter). A plain LLT of (A + A^T)/2 first; on failure retries with eps * mean(diag) added, eps = 1e-12, 1e-10, 1e-8; status Failed when all fail (L is then unusable).
    """
def sigma_points(mean: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], cov: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], scheme: SigmaScheme) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
    """
    Sigma points of N(mean, cov) as rows, shape (2n+1, n), in the order of FilterPy's MerweScaledSigmaPoints: centre, +gamma columns of L, -gamma columns.
    """
def wrap_angle(a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
    """
    Wraps angles (rad) to (-pi, pi].
    """
SPEED_OF_LIGHT: float = 299792458.0
