"""
Noise distributions: pdf, sampling, Gaussian-quantile transform.
"""
from __future__ import annotations
import nlosloc._core.core
import numpy
import numpy.typing
import typing
__all__: list[str] = ['AsymmetricNormal', 'Beta', 'Distribution', 'Empirical', 'Exponential', 'Gev', 'Normal', 'Rayleigh', 'ShiftedNormal', 'TruncatedNormal']
class Normal:
    """
    Normal distribution N(mean, std^2).
    
    LOS noise of every paper (Huerta Table VIII, Ke & Wu Sec. 6); soft-NLOS delay of Grisales (0.35 ns, 0.07 ns).
    
    Parameters
    ----------
    mean : float
        Mean, finite (unit of x). Also returned by ``mean()``.
    std : float
        Standard deviation > 0 (unit of x).
    """
    def __getstate__(self) -> tuple[float, float]:
        ...
    def __init__(self, mean: typing.SupportsFloat | typing.SupportsIndex, std: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def std(self) -> float:
        """
        Standard deviation.
        """
class Rayleigh:
    """
    Rayleigh distribution with scale s.
    
    pdf x / s^2 exp(-x^2 / (2 s^2)) for x >= 0; mean s sqrt(pi/2), variance (4 - pi)/2 s^2. NLOS TOA error of
    Huerta Table VIII (variance 2000 m^2) and Table X (5000 m^2): use ``Rayleigh.from_variance``.
    
    Parameters
    ----------
    scale : float
        Scale s > 0 (unit of x).
    """
    @staticmethod
    def from_variance(variance: typing.SupportsFloat | typing.SupportsIndex) -> Rayleigh:
        """
        Rayleigh with the given variance: scale = sqrt(2 variance / (4 - pi)).
        
        Parameters
        ----------
        variance : float
            Variance > 0 (unit of x squared).
        
        Returns
        -------
        Rayleigh
        """
    def __getstate__(self) -> tuple[float]:
        ...
    def __init__(self, scale: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def scale(self) -> float:
        """
        Scale s.
        """
class Exponential:
    """
    Exponential distribution with mean m.
    
    pdf exp(-x/m)/m for x >= 0, variance m^2. NLOS range error of Ke & Wu Sec. 6.4 (mean 0.08 d_i).
    
    Parameters
    ----------
    mean : float
        Mean m > 0 (unit of x); the rate is 1/m. Also returned by ``mean()``.
    """
    def __getstate__(self) -> tuple[float]:
        ...
    def __init__(self, mean: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
class Gev:
    """
    Generalized extreme value distribution GEV(shape k, loc mu, scale sigma).
    
    cdf exp(-(1 + k (x - mu)/sigma)^(-1/k)) where 1 + k (x - mu)/sigma > 0; Gumbel at k = 0 (Coles 2001 eq. 3.2).
    k > 0 is the heavy (Frechet) upper tail, as in Grisales Sec. 5 (hard NLOS: k = 0.4, mu = 8.5 ns,
    sigma = 4.25 ns). scipy.stats.genextreme uses the opposite sign: ``genextreme(c=-k, loc=mu, scale=sigma)``.
    The mean is inf for k >= 1, the variance inf for k >= 1/2.
    
    Parameters
    ----------
    shape : float
        Shape k, finite.
    loc : float
        Location mu, finite (unit of x).
    scale : float
        Scale sigma > 0 (unit of x).
    """
    def __getstate__(self) -> tuple[float, float, float]:
        ...
    def __init__(self, shape: typing.SupportsFloat | typing.SupportsIndex, loc: typing.SupportsFloat | typing.SupportsIndex, scale: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def loc(self) -> float:
        """
        Location mu.
        """
    @property
    def scale(self) -> float:
        """
        Scale sigma.
        """
    @property
    def shape(self) -> float:
        """
        Shape k (k > 0: heavy upper tail).
        """
class TruncatedNormal:
    """
    Normal N(mu, sigma^2) truncated to [lower, upper].
    
    Bias prior of Giremus & Grolleau Sec. 5 (N(2000, 2000^2/9) on x > 0). Equals
    ``scipy.stats.truncnorm((lower - mu)/sigma, (upper - mu)/sigma, loc=mu, scale=sigma)``.
    
    Parameters
    ----------
    mu : float
        Mean of the parent normal, finite (unit of x).
    sigma : float
        Standard deviation of the parent normal > 0 (unit of x).
    lower : float
        Lower bound, may be -inf.
    upper : float
        Upper bound > lower, may be inf.
    """
    def __getstate__(self) -> tuple[float, float, float, float]:
        ...
    def __init__(self, mu: typing.SupportsFloat | typing.SupportsIndex, sigma: typing.SupportsFloat | typing.SupportsIndex, lower: typing.SupportsFloat | typing.SupportsIndex, upper: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def lower(self) -> float:
        """
        Lower bound.
        """
    @property
    def mu(self) -> float:
        """
        Mean of the parent normal.
        """
    @property
    def sigma(self) -> float:
        """
        Standard deviation of the parent normal.
        """
    @property
    def upper(self) -> float:
        """
        Upper bound.
        """
class ShiftedNormal:
    """
    Normal N(shift, std^2) with a positive mean: an NLOS bias.
    
    Ke & Wu Sec. 6.1: N(513 m, 436^2 m^2).
    
    Parameters
    ----------
    shift : float
        Mean (the bias) > 0 (unit of x).
    std : float
        Standard deviation > 0 (unit of x).
    """
    def __getstate__(self) -> tuple[float, float]:
        ...
    def __init__(self, shift: typing.SupportsFloat | typing.SupportsIndex, std: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def shift(self) -> float:
        """
        Mean shift (bias).
        """
    @property
    def std(self) -> float:
        """
        Standard deviation.
        """
class AsymmetricNormal:
    """
    Asymmetric (split, two-piece) normal of Cong & Zhuang 2005.
    
    pdf 2 / (sqrt(2 pi) (sl + sr)) exp(-(x - mode)^2 / (2 s^2)) with s = sl left of the mode and s = sr right of it.
    Mean mode + sqrt(2/pi) (sr - sl), variance (1 - 2/pi) (sr - sl)^2 + sl sr (Wallis 2014).
    
    Parameters
    ----------
    mode : float
        Mode, finite (unit of x).
    sigma_left : float
        Standard deviation left of the mode, > 0.
    sigma_right : float
        Standard deviation right of the mode, > 0.
    """
    @staticmethod
    def fit(samples: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> AsymmetricNormal:
        """
        Maximum-likelihood fit (Villani & Larsson 2006 profile likelihood).
        
        For a mode m the ML sigmas are closed-form; the mode minimises S_l^(1/3) + S_r^(1/3) (sums of squared
        deviations left / right of m), searched over the samples and refined by golden section.
        
        Parameters
        ----------
        samples : numpy.ndarray
            Shape (n,), n >= 3 finite values, not all equal.
        
        Returns
        -------
        AsymmetricNormal
        """
    def __getstate__(self) -> tuple[float, float, float]:
        ...
    def __init__(self, mode: typing.SupportsFloat | typing.SupportsIndex, sigma_left: typing.SupportsFloat | typing.SupportsIndex, sigma_right: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def mode(self) -> float:
        """
        Mode.
        """
    @property
    def sigma_left(self) -> float:
        """
        Standard deviation left of the mode.
        """
    @property
    def sigma_right(self) -> float:
        """
        Standard deviation right of the mode.
        """
class Beta:
    """
    Beta(a, b) distribution on [0, 1].
    
    Quality statistics of Grisales Fig. 2: LOS Beta(4, 1.5), soft NLOS Beta(3, 1.5), hard NLOS Beta(1.5, 4).
    
    Parameters
    ----------
    a : float
        First shape parameter > 0.
    b : float
        Second shape parameter > 0.
    """
    def __getstate__(self) -> tuple[float, float]:
        ...
    def __init__(self, a: typing.SupportsFloat | typing.SupportsIndex, b: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def a(self) -> float:
        """
        First shape parameter.
        """
    @property
    def b(self) -> float:
        """
        Second shape parameter.
        """
class Empirical:
    """
    Gaussian kernel density of samples (Silverman's bandwidth).
    
    The same density as ``scipy.stats.gaussian_kde(samples, bw_method="silverman")``: bandwidth
    h = std(samples, ddof=1) * (3 n / 4)^(-1/5). ``mean()`` is the sample mean and ``variance()`` is
    var(samples, ddof=0) + h^2, the variance of the smoothed density.
    
    Parameters
    ----------
    samples : numpy.ndarray
        Shape (n,), n >= 2 finite values with a nonzero spread (unit of x).
    """
    def __getstate__(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        ...
    def __init__(self, samples: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def bandwidth(self) -> float:
        """
        Kernel bandwidth h (unit of x).
        """
    @property
    def samples(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        The samples, sorted ascending, shape (n,).
        """
    @property
    def size(self) -> int:
        """
        Number of samples n.
        """
class Distribution:
    """
    Any of the noise distributions, behind one type.
    
    Every function of nlosloc that takes a Distribution also accepts a Normal, Rayleigh, Exponential, Gev,
    TruncatedNormal, ShiftedNormal, AsymmetricNormal, Beta or Empirical directly.
    
    Parameters
    ----------
    dist : Normal | Rayleigh | Exponential | Gev | TruncatedNormal | ShiftedNormal | AsymmetricNormal | Beta | Empirical, optional
        The distribution held; the default is Normal(0, 1).
    """
    def __getstate__(self) -> tuple[typing.Any]:
        ...
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, dist: Normal) -> None:
        ...
    @typing.overload
    def __init__(self, dist: Rayleigh) -> None:
        ...
    @typing.overload
    def __init__(self, dist: Exponential) -> None:
        ...
    @typing.overload
    def __init__(self, dist: Gev) -> None:
        ...
    @typing.overload
    def __init__(self, dist: TruncatedNormal) -> None:
        ...
    @typing.overload
    def __init__(self, dist: ShiftedNormal) -> None:
        ...
    @typing.overload
    def __init__(self, dist: AsymmetricNormal) -> None:
        ...
    @typing.overload
    def __init__(self, dist: Beta) -> None:
        ...
    @typing.overload
    def __init__(self, dist: Empirical) -> None:
        ...
    @typing.overload
    def __init__(self, dist: Distribution) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def cdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Cumulative distribution function P(X <= x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Probabilities in [0, 1], same shape as `x`.
        """
    def from_standard_normal(self, u: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).
        
        Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
        quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.
        
        Parameters
        ----------
        u : float or numpy.ndarray
            Standard normal values, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            Transformed values, same shape as `u`.
        """
    def log_pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Log density.
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape, in the unit of the distribution.
        
        Returns
        -------
        float or numpy.ndarray
            log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
        """
    def mean(self) -> float:
        """
        Mean of the distribution (inf when it does not exist).
        """
    def name(self) -> str:
        """
        Class name, e.g. 'Rayleigh'.
        """
    def pdf(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Density p(x).
        
        Parameters
        ----------
        x : float or numpy.ndarray
            Points, any shape.
        
        Returns
        -------
        float or numpy.ndarray
            p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
        """
    def quantile(self, p: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Any:
        """
        Inverse cdf.
        
        Parameters
        ----------
        p : float or numpy.ndarray
            Probabilities in the open interval (0, 1), any shape.
        
        Returns
        -------
        float or numpy.ndarray
            x with P(X <= x) = p, same shape as `p`.
        
        Raises
        ------
        ValueError
            If a probability is outside (0, 1).
        """
    def sample(self, rng: nlosloc._core.core.Rng, size: typing.SupportsInt | typing.SupportsIndex | None = None) -> typing.Any:
        """
        Random draws.
        
        Parameters
        ----------
        rng : nlosloc.core.Rng
            Generator; advanced by the draws.
        size : int, optional
            Number of draws. None (default) returns one float.
        
        Returns
        -------
        float or numpy.ndarray
            One draw, or an array of shape (size,).
        """
    def variance(self) -> float:
        """
        Variance of the distribution (inf when it does not exist).
        """
    @property
    def value(self) -> typing.Any:
        """
        The concrete distribution held (a copy).
        """
