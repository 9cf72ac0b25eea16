#pragma once
/// \file noise.hpp
/// Scalar noise distributions of the LOS / NLOS measurement models: normal, Rayleigh, exponential,
/// generalized extreme value, truncated normal, shifted normal, asymmetric (split) normal, Beta and an
/// empirical (Gaussian kernel density) distribution, plus the type-erased `Distribution`.
///
/// Every class is a small immutable value type with a validating constructor and the same const methods:
/// log_pdf, pdf, cdf, quantile, mean, variance, sample, from_standard_normal, name. from_standard_normal(u)
/// is the Gaussian-quantile transform x = F^{-1}(Phi(u)) through which non-Gaussian noise enters the
/// sigma-point filters as an augmented standard normal variable (Huerta 2009 Sec. V-A; Grisales eq. 29).
/// It is computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the
/// complementary quantile, so u = 8 maps to a distinct point of the upper tail instead of collapsing to
/// F^{-1}(1).
///
/// Conventions: log_pdf outside the support is -inf (no throw), NaN in gives NaN out; quantile(p) needs
/// p in (0, 1) and throws std::invalid_argument otherwise. Special functions and standard quantiles come
/// from Boost.Math with a policy that returns IEEE values (inf, NaN) instead of throwing.
#include <algorithm>
#include <boost/math/distributions/beta.hpp>
#include <boost/math/distributions/complement.hpp>
#include <boost/math/distributions/exponential.hpp>
#include <boost/math/distributions/extreme_value.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/rayleigh.hpp>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/special_functions/beta.hpp>
#include <boost/math/special_functions/gamma.hpp>
#include <boost/math/special_functions/zeta.hpp>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nlosloc/core/random.hpp"
#include "nlosloc/core/types.hpp"

namespace nlosloc::noise {

namespace detail {

namespace bmp = boost::math::policies;
/// Boost.Math policy: domain, pole, overflow and evaluation errors return NaN / inf instead of throwing, and
/// double is not promoted to long double internally (10x faster Beta quantiles, still within a few ulps).
using Policy = bmp::policy<bmp::domain_error<bmp::ignore_error>, bmp::pole_error<bmp::ignore_error>,
                           bmp::overflow_error<bmp::ignore_error>, bmp::underflow_error<bmp::ignore_error>,
                           bmp::evaluation_error<bmp::ignore_error>, bmp::rounding_error<bmp::ignore_error>,
                           bmp::promote_double<false>>;

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// log(sqrt(2 pi)).
inline constexpr double kLogSqrt2Pi = 0.91893853320467274178;
/// Euler-Mascheroni constant (mean of the standard Gumbel).
inline constexpr double kEulerGamma = 0.57721566490153286061;

/// Shortest round-trip text of a double ("-1", "0.25", "inf", "nan") for error messages.
inline std::string fmt(double v) { return nlosloc::detail::fmt_shortest(v); }
/// Throws "<cls>: <arg>: expected a finite value > 0, got <v>" unless v is finite and > 0.
inline void check_positive(const char* cls, const char* arg, double v) {
  if (!(v > 0.0) || !std::isfinite(v))
    nlosloc::detail::throw_invalid_argument(std::string(cls) + ": " + arg +
                                            ": expected a finite value > 0, got " + fmt(v));
}
/// Throws "<cls>: <arg>: expected a finite value, got <v>" unless v is finite.
inline void check_finite(const char* cls, const char* arg, double v) {
  if (!std::isfinite(v))
    nlosloc::detail::throw_invalid_argument(std::string(cls) + ": " + arg +
                                            ": expected a finite value, got " + fmt(v));
}

/// Standard normal distribution of Boost with the IEEE policy.
inline const boost::math::normal_distribution<double, Policy>& std_normal() {
  static const boost::math::normal_distribution<double, Policy> n(0.0, 1.0);
  return n;
}
/// Phi(z), accurate in the lower tail (erfc based).
inline double phi_cdf(double z) { return boost::math::cdf(std_normal(), z); }
/// 1 - Phi(z), accurate in the upper tail.
inline double phi_sf(double z) { return boost::math::cdf(boost::math::complement(std_normal(), z)); }
/// Standard normal density.
inline double phi_pdf(double z) { return std::exp(-0.5 * z * z - kLogSqrt2Pi); }
/// Phi^{-1}(p) for p in [0, 1]; -inf at 0, +inf at 1; accurate for small p.
inline double phi_inv(double p) {
  if (p <= 0.0) return -kInf;
  if (p >= 1.0) return kInf;
  return boost::math::quantile(std_normal(), p);
}
/// z with 1 - Phi(z) = q for q in [0, 1]; accurate for small q.
inline double phi_inv_upper(double q) {
  if (q <= 0.0) return kInf;
  if (q >= 1.0) return -kInf;
  return boost::math::quantile(boost::math::complement(std_normal(), q));
}
/// Standard normal mass of [lo, hi] (lo <= hi) with relative accuracy: a short interval (width times its
/// distance from 0 below 1/2, where the difference of tail probabilities would cancel) is integrated by
/// 10-point Gauss-Legendre; otherwise the difference is taken in the tail where both terms are small.
inline double phi_mass(double lo, double hi) {
  const double w = hi - lo;
  if (w * (1.0 + std::max(std::abs(lo), std::abs(hi))) < 0.5)
    return boost::math::quadrature::gauss<double, 10>::integrate([](double t) { return phi_pdf(t); }, lo, hi);
  if (lo >= 0.0) return phi_sf(lo) - phi_sf(hi);
  if (hi <= 0.0) return phi_cdf(hi) - phi_cdf(lo);
  return 1.0 - phi_cdf(lo) - phi_sf(hi);
}

/// Standard normal mass between a and a + dir * d (dir = +1 or -1, d >= 0), relatively accurate also when d
/// is tiny, because the width d is used as given instead of being recovered from a rounded end point.
inline double phi_mass_span(double a, double d, int dir) {
  if (!(d > 0.0)) return 0.0;
  if (d * (1.0 + std::abs(a) + d) < 0.5)
    return boost::math::quadrature::gauss<double, 10>::integrate(
        [&](double t) { return phi_pdf(a + dir * t); }, 0.0, d);
  return dir > 0 ? phi_mass(a, a + d) : phi_mass(a - d, a);
}

/// Shared methods of the distributions (CRTP). Derived provides kName, log_pdf, and two private tail-accurate
/// quantile helpers: quantile_lower_(p) solves P(X <= x) = p and quantile_upper_(q) solves P(X > x) = q,
/// each accurate when its argument is small and defined at 0 (the support bound, possibly infinite).
template <class Derived>
class DistributionBase {
 public:
  /// Density exp(log_pdf(x)); 0 outside the support.
  double pdf(double x) const { return std::exp(self().log_pdf(x)); }
  /// Inverse cdf, p in (0, 1); throws std::invalid_argument otherwise.
  double quantile(double p) const {
    if (!(p > 0.0 && p < 1.0))
      nlosloc::detail::throw_invalid_argument(
          std::string(Derived::kName) + "::quantile: p: expected a probability in (0, 1), got " + fmt(p));
    // 1 - p is exact for p >= 0.5 (Sterbenz), so the upper helper sees the exact tail probability.
    return p <= 0.5 ? self().quantile_lower_(p) : self().quantile_upper_(1.0 - p);
  }
  /// F^{-1}(Phi(u)), tail-safe: u > 0 inverts the upper-tail probability Phi(-u) (Huerta Sec. V-A).
  double from_standard_normal(double u) const {
    if (std::isnan(u)) return u;
    return u <= 0.0 ? self().quantile_lower_(phi_cdf(u)) : self().quantile_upper_(phi_cdf(-u));
  }
  /// One draw by inversion of a uniform variate in (0, 1).
  double sample(Rng& rng) const {
    const double u = rng.uniform();
    return u <= 0.5 ? self().quantile_lower_(u) : self().quantile_upper_(1.0 - u);
  }
  /// Class name ("Normal", "Rayleigh", ...).
  const char* name() const { return Derived::kName; }

 private:
  const Derived& self() const { return static_cast<const Derived&>(*this); }
};

/// Safeguarded Newton on an increasing function f with derivative df in the bracket [lo, hi] with
/// f(lo) <= 0 <= f(hi): Newton steps that leave the bracket are replaced by bisection. Stops when the step or
/// the bracket is below tol_rel * (|x| + scale).
template <class F, class DF>
double solve_increasing(F f, DF df, double lo, double hi, double x, double scale, double tol_rel = 1e-12) {
  if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    const double fx = f(x);
    if (fx == 0.0) return x;
    if (fx < 0.0)
      lo = x;
    else
      hi = x;
    const double tol = tol_rel * (std::abs(x) + scale);
    if (hi - lo <= tol) return 0.5 * (lo + hi);
    const double d = df(x);
    double xn = d > 0.0 ? x - fx / d : kNaN;
    if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
    if (std::abs(xn - x) <= tol) return xn;
    x = xn;
  }
  return x;
}

}  // namespace detail

/// Normal N(mean, std^2). LOS noise of every paper (Huerta Table VIII; Ke & Wu Sec. 6; Grisales soft NLOS
/// delay Normal(0.35 ns, 0.07 ns)).
class Normal : public detail::DistributionBase<Normal> {
 public:
  static constexpr const char* kName = "Normal";
  /// mean finite, std > 0 (same unit as x).
  Normal(double mean, double std) : mean_(mean), std_(std) {
    detail::check_finite(kName, "mean", mean);
    detail::check_positive(kName, "std", std);
  }
  /// Mean parameter (also the distribution mean).
  double mean() const { return mean_; }
  /// Standard deviation parameter.
  double stddev() const { return std_; }
  /// Variance std^2.
  double variance() const { return std_ * std_; }
  /// log N(x; mean, std^2) = -z^2/2 - log(std sqrt(2 pi)).
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    const double z = (x - mean_) / std_;
    return -0.5 * z * z - std::log(std_) - detail::kLogSqrt2Pi;
  }
  /// Phi((x - mean)/std).
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    return detail::phi_cdf((x - mean_) / std_);
  }
  /// Exactly mean + std * u.
  double from_standard_normal(double u) const { return mean_ + std_ * u; }
  /// mean + std * rng.normal().
  double sample(Rng& rng) const { return mean_ + std_ * rng.normal(); }

 private:
  friend class detail::DistributionBase<Normal>;
  double quantile_lower_(double p) const { return mean_ + std_ * detail::phi_inv(p); }
  double quantile_upper_(double q) const { return mean_ + std_ * detail::phi_inv_upper(q); }
  double mean_, std_;
};

/// Rayleigh with scale s: pdf x/s^2 exp(-x^2/(2 s^2)), x >= 0; mean s sqrt(pi/2), variance (4 - pi)/2 s^2
/// (Johnson, Kotz & Balakrishnan, Continuous Univariate Distributions vol. 1, ch. 18). NLOS TOA error of
/// Huerta Table VIII (variance 2000 m^2) and Table X (RTOA, 5000 m^2).
class Rayleigh : public detail::DistributionBase<Rayleigh> {
 public:
  static constexpr const char* kName = "Rayleigh";
  /// scale > 0 (same unit as x).
  explicit Rayleigh(double scale) : scale_(scale) { detail::check_positive(kName, "scale", scale); }
  /// Rayleigh whose variance is `variance` > 0: scale = sqrt(2 variance / (4 - pi)) (Huerta Table VIII).
  static Rayleigh from_variance(double variance) {
    detail::check_positive(kName, "variance", variance);
    return Rayleigh(std::sqrt(2.0 * variance / (4.0 - kPi)));
  }
  /// Scale parameter s.
  double scale() const { return scale_; }
  /// s sqrt(pi/2).
  double mean() const { return scale_ * std::sqrt(0.5 * kPi); }
  /// (4 - pi)/2 s^2.
  double variance() const { return 0.5 * (4.0 - kPi) * scale_ * scale_; }
  /// log(x/s^2) - x^2/(2 s^2) for x > 0, -inf otherwise (the density is 0 at x = 0).
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    if (!(x > 0.0) || std::isinf(x)) return -detail::kInf;
    const double z = x / scale_;
    return std::log(z) - std::log(scale_) - 0.5 * z * z;
  }
  /// 1 - exp(-x^2/(2 s^2)) via expm1.
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    if (x <= 0.0) return 0.0;
    const double z = x / scale_;
    return -std::expm1(-0.5 * z * z);
  }

 private:
  friend class detail::DistributionBase<Rayleigh>;
  boost::math::rayleigh_distribution<double, detail::Policy> dist() const {
    return boost::math::rayleigh_distribution<double, detail::Policy>(scale_);
  }
  double quantile_lower_(double p) const { return p <= 0.0 ? 0.0 : boost::math::quantile(dist(), p); }
  double quantile_upper_(double q) const {
    return q <= 0.0 ? detail::kInf : boost::math::quantile(boost::math::complement(dist(), q));
  }
  double scale_;
};

/// Exponential with mean m: pdf exp(-x/m)/m, x >= 0; variance m^2. NLOS range error of Ke & Wu Sec. 6.4
/// (K3: mean 0.08 d_i) and of Cong & Zhuang 2001.
class Exponential : public detail::DistributionBase<Exponential> {
 public:
  static constexpr const char* kName = "Exponential";
  /// mean > 0 (same unit as x); the rate is 1/mean.
  explicit Exponential(double mean) : mean_(mean) { detail::check_positive(kName, "mean", mean); }
  /// Mean parameter m.
  double mean() const { return mean_; }
  /// m^2.
  double variance() const { return mean_ * mean_; }
  /// -log m - x/m for x >= 0, -inf otherwise.
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    if (x < 0.0 || std::isinf(x)) return -detail::kInf;
    return -std::log(mean_) - x / mean_;
  }
  /// 1 - exp(-x/m) via expm1.
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    return x <= 0.0 ? 0.0 : -std::expm1(-x / mean_);
  }

 private:
  friend class detail::DistributionBase<Exponential>;
  boost::math::exponential_distribution<double, detail::Policy> dist() const {
    return boost::math::exponential_distribution<double, detail::Policy>(1.0 / mean_);
  }
  double quantile_lower_(double p) const { return p <= 0.0 ? 0.0 : boost::math::quantile(dist(), p); }
  double quantile_upper_(double q) const {
    return q <= 0.0 ? detail::kInf : boost::math::quantile(boost::math::complement(dist(), q));
  }
  double mean_;
};

/// Generalized extreme value GEV(k, mu, sigma): cdf exp(-(1 + k (x - mu)/sigma)^(-1/k)) on 1 + k(x-mu)/sigma
/// > 0, Gumbel exp(-exp(-(x - mu)/sigma)) at k = 0 (Coles 2001, An Introduction to Statistical Modeling of
/// Extreme Values, eq. 3.2). Shape k > 0 is the heavy (Frechet) tail, as in Grisales Sec. 5 (hard-NLOS delay
/// GEV(k = 0.4, mu = 8.5 ns, sigma = 4.25 ns)). scipy.stats.genextreme uses the opposite sign: c = -k.
/// Mean is +inf for k >= 1 and the variance +inf for k >= 1/2.
class Gev : public detail::DistributionBase<Gev> {
 public:
  static constexpr const char* kName = "Gev";
  /// shape k finite (k > 0 heavy upper tail), loc mu finite, scale sigma > 0.
  Gev(double shape, double loc, double scale) : k_(shape), mu_(loc), sigma_(scale) {
    detail::check_finite(kName, "shape", shape);
    detail::check_finite(kName, "loc", loc);
    detail::check_positive(kName, "scale", scale);
    init_moments();
  }
  /// Shape k.
  double shape() const { return k_; }
  /// Location mu.
  double loc() const { return mu_; }
  /// Scale sigma.
  double scale() const { return sigma_; }
  /// mu + sigma (Gamma(1 - k) - 1)/k (k < 1), mu + sigma * euler_gamma (k = 0), +inf for k >= 1 (Coles
  /// Sec. 3.1).
  double mean() const { return mean_; }
  /// sigma^2 (g2 - g1^2)/k^2 with g_j = Gamma(1 - j k) (k < 1/2), sigma^2 pi^2/6 (k = 0), +inf for k >= 1/2.
  double variance() const { return var_; }
  /// log pdf = -log sigma + (k + 1) log t - t with t = (1 + k z)^(-1/k), z = (x - mu)/sigma (t = exp(-z) at
  /// k = 0); -inf outside the support 1 + k z > 0.
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    if (std::isinf(x)) return -detail::kInf;
    const double lt = log_t(x);
    if (std::isnan(lt)) return -detail::kInf;  // outside the support
    return -std::log(sigma_) + (k_ + 1.0) * lt - std::exp(lt);
  }
  /// exp(-t) (Coles eq. 3.2); 0 below / 1 above the support.
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    if (k_ != 0.0 && !(1.0 + k_ * (x - mu_) / sigma_ > 0.0)) return k_ > 0.0 ? 0.0 : 1.0;
    if (k_ == 0.0) return boost::math::cdf(gumbel(), x);
    return std::exp(-std::exp(log_t(x)));
  }

 private:
  friend class detail::DistributionBase<Gev>;
  boost::math::extreme_value_distribution<double, detail::Policy> gumbel() const {
    return boost::math::extreme_value_distribution<double, detail::Policy>(mu_, sigma_);
  }
  /// log t = -log1p(k z)/k, continuous as k -> 0; NaN outside the support.
  double log_t(double x) const {
    const double z = (x - mu_) / sigma_;
    if (k_ == 0.0) return -z;
    const double kz = k_ * z;
    if (!(kz > -1.0)) return detail::kNaN;
    return -std::log1p(kz) / k_;
  }
  /// x = mu + sigma ((-log p)^(-k) - 1)/k written as expm1(-k log y)/k, y = -log p (closed-form GEV
  /// quantile).
  double from_y(double y) const {
    if (k_ == 0.0) return mu_ - sigma_ * std::log(y);
    return mu_ + sigma_ * std::expm1(-k_ * std::log(y)) / k_;
  }
  double quantile_lower_(double p) const {
    if (k_ == 0.0) return p <= 0.0 ? -detail::kInf : boost::math::quantile(gumbel(), p);
    return from_y(-std::log(p));
  }
  double quantile_upper_(double q) const {
    if (k_ == 0.0)
      return q <= 0.0 ? detail::kInf : boost::math::quantile(boost::math::complement(gumbel(), q));
    return from_y(-std::log1p(-q));
  }
  void init_moments() {
    if (k_ >= 1.0) {
      mean_ = var_ = detail::kInf;
      return;
    }
    // (Gamma(1 - k) - 1)/k via tgamma1pm1, accurate as k -> 0; the limit is euler_gamma.
    const double c1 = k_ == 0.0 ? detail::kEulerGamma : boost::math::tgamma1pm1(-k_, detail::Policy()) / k_;
    mean_ = mu_ + sigma_ * c1;
    if (k_ >= 0.5) {
      var_ = detail::kInf;
      return;
    }
    if (k_ == 0.0) {
      var_ = sigma_ * sigma_ * kPi * kPi / 6.0;
      return;
    }
    // (g2 - g1^2)/k^2 = g1^2 expm1(D)/k^2 with D = lgamma(1 - 2k) - 2 lgamma(1 - k). For small |k| the
    // Taylor series lgamma(1 + x) = -gamma x + sum_{n>=2} (-1)^n zeta(n) x^n / n gives, with the Euler terms
    // cancelling exactly, D = sum_{n>=2} zeta(n) (2^n - 2) k^n / n (Abramowitz & Stegun 6.1.33).
    double d = 0.0;
    if (std::abs(k_) < 0.05) {
      double kn = k_;
      double two_n = 2.0;
      for (int n = 2; n <= 60; ++n) {
        kn *= k_;
        two_n *= 2.0;
        const double term =
            boost::math::zeta(static_cast<double>(n), detail::Policy()) * (two_n - 2.0) * kn / n;
        d += term;
        if (std::abs(term) <= 1e-18 * std::abs(d)) break;
      }
    } else {
      d = boost::math::lgamma(1.0 - 2.0 * k_, detail::Policy()) -
          2.0 * boost::math::lgamma(1.0 - k_, detail::Policy());
    }
    const double g1 = boost::math::tgamma(1.0 - k_, detail::Policy());
    var_ = sigma_ * sigma_ * g1 * g1 * std::expm1(d) / (k_ * k_);
  }
  double k_, mu_, sigma_;
  double mean_ = 0.0, var_ = 0.0;
};

/// Normal N(mu, sigma^2) truncated to [lower, upper] (Johnson, Kotz & Balakrishnan vol. 1 ch. 13). Bias prior
/// of Giremus & Grolleau Sec. 5 (N(2000, 2000^2/9) and N(40, 40^2/9) truncated to positive values).
/// Probabilities use the standard-normal mass evaluated in the tail where it is small, and next to a finite
/// bound the mass of the exact offset from it, so intervals far in a tail keep their relative accuracy as
/// long as their mass is a normal double (standardised bounds up to about 37; the constructor checks this).
class TruncatedNormal : public detail::DistributionBase<TruncatedNormal> {
 public:
  static constexpr const char* kName = "TruncatedNormal";
  /// mu finite, sigma > 0, lower < upper (either may be infinite, neither NaN).
  TruncatedNormal(double mu, double sigma, double lower, double upper)
      : mu_(mu), sigma_(sigma), lower_(lower), upper_(upper) {
    detail::check_finite(kName, "mu", mu);
    detail::check_positive(kName, "sigma", sigma);
    if (std::isnan(lower) || lower == detail::kInf)
      nlosloc::detail::throw_invalid_argument(std::string(kName) + ": lower: expected a value < +inf, got " +
                                              detail::fmt(lower));
    if (std::isnan(upper) || upper == -detail::kInf)
      nlosloc::detail::throw_invalid_argument(std::string(kName) + ": upper: expected a value > -inf, got " +
                                              detail::fmt(upper));
    if (!(lower < upper))
      nlosloc::detail::throw_invalid_argument(
          std::string(kName) + ": lower, upper: expected lower < upper, got lower=" + detail::fmt(lower) +
          ", upper=" + detail::fmt(upper));
    alpha_ = (lower - mu) / sigma;
    beta_ = (upper - mu) / sigma;
    z_ = detail::phi_mass(alpha_, beta_);
    if (!(z_ >= std::numeric_limits<double>::min()))
      nlosloc::detail::throw_invalid_argument(
          std::string(kName) +
          ": lower, upper: the interval holds no representable probability mass of N(mu, sigma^2) "
          "(standardised bounds " +
          detail::fmt(alpha_) + ", " + detail::fmt(beta_) + ")");
    log_z_ = std::log(z_);
    var_ = sigma_ * sigma_ * standard_variance();
  }
  /// Mean of the parent normal.
  double mu() const { return mu_; }
  /// Standard deviation of the parent normal.
  double sigma() const { return sigma_; }
  /// Lower bound (may be -inf).
  double lower() const { return lower_; }
  /// Upper bound (may be +inf).
  double upper() const { return upper_; }
  /// mu + sigma (phi(alpha) - phi(beta))/Z (JKB eq. 13.134).
  double mean() const { return mu_ + sigma_ * (detail::phi_pdf(alpha_) - detail::phi_pdf(beta_)) / z_; }
  /// sigma^2 times the variance of N(0, 1) on [alpha, beta]: JKB eq. 13.135 where it is at least 1/4, else
  /// by quadrature (standard_variance), to about 1e-14 relative either way.
  double variance() const { return var_; }
  /// log phi(z) - log sigma - log Z on [lower, upper], -inf outside.
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    if (x < lower_ || x > upper_ || std::isinf(x)) return -detail::kInf;
    const double z = (x - mu_) / sigma_;
    return -0.5 * z * z - detail::kLogSqrt2Pi - std::log(sigma_) - log_z_;
  }
  /// mass(alpha, z)/Z; next to a finite lower bound the mass is integrated over the exact offset x - lower.
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    if (x <= lower_) return 0.0;
    if (x >= upper_) return 1.0;
    const double mass = std::isfinite(lower_) ? detail::phi_mass_span(alpha_, (x - lower_) / sigma_, +1)
                                              : detail::phi_cdf((x - mu_) / sigma_);
    return std::min(1.0, mass / z_);
  }

 private:
  friend class detail::DistributionBase<TruncatedNormal>;
  static double xphi(double a) { return std::isinf(a) ? 0.0 : a * detail::phi_pdf(a); }
  /// Variance of N(0, 1) on [alpha, beta]. JKB eq. 13.135, 1 + (alpha phi(alpha) - beta phi(beta))/Z -
  /// ((phi(alpha) - phi(beta))/Z)^2, sums terms of order alpha^2 to a small variance: 2e-5 relative error
  /// on [5, 5.001], 5e-8 on [30, inf). Below 1/4 the moments are integrated instead, in the offset u from the
  /// density's mode c, where it is exp(-c u - u^2/2) up to a constant (no cancellation): 16-point
  /// Gauss-Legendre on 16 equal pieces of each side of c, cut where the density falls below e^-40 of its
  /// mode.
  double standard_variance() const {
    const double r = (detail::phi_pdf(alpha_) - detail::phi_pdf(beta_)) / z_;
    const double s = (xphi(alpha_) - xphi(beta_)) / z_;
    const double closed = 1.0 + s - r * r;
    if (closed >= 0.25) return closed;
    // The interval's width from the bounds themselves: beta - alpha would carry the rounding of each.
    const double width =
        std::isfinite(lower_) && std::isfinite(upper_) ? (upper_ - lower_) / sigma_ : detail::kInf;
    double a = alpha_, b = beta_;
    if (b <= 0.0) {  // mirror: the variance is the same
      std::swap(a, b);
      a = -a;
      b = -b;
    }
    double c = 0.0, lo = 0.0, hi = 0.0;
    if (a >= 0.0) {  // mode at the lower bound; the cut at u = sqrt(c^2 + 80) - c, written without cancelling
      c = a;
      hi = std::min(width, 80.0 / (std::sqrt(c * c + 80.0) + c));
    } else {
      lo = std::max(a, -std::sqrt(80.0));
      hi = std::min(b, std::sqrt(80.0));
    }
    static constexpr double kNode[8] = {0.09501250983763744, 0.2816035507792589, 0.45801677765722737,
                                        0.6178762444026438,  0.755404408355003,  0.8656312023878318,
                                        0.9445750230732326,  0.9894009349916499};
    static constexpr double kWeight[8] = {0.18945061045506864,  0.18260341504492364, 0.16915651939500265,
                                          0.1495959888165767,   0.12462897125553407, 0.0951585116824926,
                                          0.062253523938647456, 0.027152459411754176};
    double m0 = 0.0, m1 = 0.0, m2 = 0.0;
    for (const auto& [from, to] : {std::pair{lo, 0.0}, std::pair{0.0, hi}}) {
      if (!(to > from)) continue;
      const double h = (to - from) / 16.0;
      for (int k = 0; k < 16; ++k) {
        const double mid = from + (k + 0.5) * h;
        for (int j = 0; j < 16; ++j) {
          const double x = j < 8 ? -kNode[7 - j] : kNode[j - 8];
          const double u = mid + 0.5 * h * x;
          const double f = 0.5 * h * kWeight[j < 8 ? 7 - j : j - 8] * std::exp(-c * u - 0.5 * u * u);
          m0 += f;
          m1 += f * u;
          m2 += f * u * u;
        }
      }
    }
    const double mean = m1 / m0;
    return m2 / m0 - mean * mean;
  }
  // mass(alpha, z) = p Z. Closed form in the tail that keeps the relative accuracy, then Newton steps on the
  // offset d = z - alpha from the bound (z itself cannot resolve a tiny offset from a bound far from 0).
  double quantile_lower_(double p) const {
    if (p <= 0.0) return lower_;
    const double m = p * z_;
    const double z = alpha_ >= 0.0 ? detail::phi_inv_upper(detail::phi_sf(alpha_) - m)
                                   : detail::phi_inv(detail::phi_cdf(alpha_) + m);
    if (!std::isfinite(lower_)) return std::min(upper_, mu_ + sigma_ * z);
    const double dmax = beta_ - alpha_;
    double d = std::min(dmax, std::max(0.0, z - alpha_));
    for (int it = 0; it < 4 && std::isfinite(d); ++it) {
      const double f = detail::phi_pdf(alpha_ + d);
      if (!(f > 0.0)) break;
      const double dn = std::min(dmax, std::max(0.0, d - (detail::phi_mass_span(alpha_, d, +1) - m) / f));
      const bool done = std::abs(dn - d) <= 1e-15 * d;
      d = dn;
      if (done) break;
    }
    return std::min(upper_, lower_ + sigma_ * d);
  }
  // mass(z, beta) = q Z, with the offset d = beta - z from a finite upper bound.
  double quantile_upper_(double q) const {
    if (q <= 0.0) return upper_;
    const double m = q * z_;
    const double z = beta_ <= 0.0 ? detail::phi_inv(detail::phi_cdf(beta_) - m)
                                  : detail::phi_inv_upper(detail::phi_sf(beta_) + m);
    if (!std::isfinite(upper_)) return std::max(lower_, mu_ + sigma_ * z);
    const double dmax = beta_ - alpha_;
    double d = std::min(dmax, std::max(0.0, beta_ - z));
    for (int it = 0; it < 4 && std::isfinite(d); ++it) {
      const double f = detail::phi_pdf(beta_ - d);
      if (!(f > 0.0)) break;
      const double dn = std::min(dmax, std::max(0.0, d - (detail::phi_mass_span(beta_, d, -1) - m) / f));
      const bool done = std::abs(dn - d) <= 1e-15 * d;
      d = dn;
      if (done) break;
    }
    return std::max(lower_, upper_ - sigma_ * d);
  }
  double mu_, sigma_, lower_, upper_;
  double alpha_ = 0.0, beta_ = 0.0, z_ = 1.0, log_z_ = 0.0, var_ = 1.0;
};

/// Normal N(shift, std^2) with a positive mean: an NLOS range bias (Ke & Wu Sec. 6.1: N(513 m, 436^2 m^2),
/// after the GSM field tests they cite).
class ShiftedNormal : public detail::DistributionBase<ShiftedNormal> {
 public:
  static constexpr const char* kName = "ShiftedNormal";
  /// shift > 0 (the NLOS bias), std > 0.
  ShiftedNormal(double shift, double std) : shift_(shift), std_(std) {
    detail::check_positive(kName, "shift", shift);
    detail::check_positive(kName, "std", std);
  }
  /// Mean shift (bias).
  double shift() const { return shift_; }
  /// Standard deviation.
  double stddev() const { return std_; }
  /// shift.
  double mean() const { return shift_; }
  /// std^2.
  double variance() const { return std_ * std_; }
  /// Normal log density about the shift.
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    const double z = (x - shift_) / std_;
    return -0.5 * z * z - std::log(std_) - detail::kLogSqrt2Pi;
  }
  /// Phi((x - shift)/std).
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    return detail::phi_cdf((x - shift_) / std_);
  }
  /// Exactly shift + std * u.
  double from_standard_normal(double u) const { return shift_ + std_ * u; }
  /// shift + std * rng.normal().
  double sample(Rng& rng) const { return shift_ + std_ * rng.normal(); }

 private:
  friend class detail::DistributionBase<ShiftedNormal>;
  double quantile_lower_(double p) const { return shift_ + std_ * detail::phi_inv(p); }
  double quantile_upper_(double q) const { return shift_ + std_ * detail::phi_inv_upper(q); }
  double shift_, std_;
};

/// Asymmetric (split, two-piece) normal used by Cong & Zhuang 2005 to fit NLOS errors (the CONG baseline of
/// Huerta Sec. VI): pdf 2/(sqrt(2 pi)(sl + sr)) exp(-(x - mode)^2/(2 s^2)), s = sl left of the mode and sr
/// right of it. Mean mode + sqrt(2/pi)(sr - sl), variance (1 - 2/pi)(sr - sl)^2 + sl sr (Wallis 2014,
/// Statistical Science 29(1), eqs. 2-3).
class AsymmetricNormal : public detail::DistributionBase<AsymmetricNormal> {
 public:
  static constexpr const char* kName = "AsymmetricNormal";
  /// mode finite, sigma_left > 0, sigma_right > 0.
  AsymmetricNormal(double mode, double sigma_left, double sigma_right)
      : mode_(mode), sl_(sigma_left), sr_(sigma_right) {
    detail::check_finite(kName, "mode", mode);
    detail::check_positive(kName, "sigma_left", sigma_left);
    detail::check_positive(kName, "sigma_right", sigma_right);
  }
  /// Maximum-likelihood fit to samples (n >= 3, finite, not all equal). For a fixed mode m the ML sigmas are
  /// sl = a sqrt((a + b)/n), sr = b sqrt((a + b)/n) with a = S_l^(1/3), b = S_r^(1/3) and S_l, S_r the sums
  /// of squared deviations from m of the samples left / right of m; the profile log-likelihood is const -
  /// (3n/2) log(a + b) (Villani & Larsson 2006, Commun. Stat. Theory Methods 35(6), Sec. 3). The mode
  /// minimises a + b: evaluated at every interior sample (prefix sums) and refined by golden section in the
  /// two intervals adjacent to the best sample. Data whose mode is the minimum (e.g. exponential) give a
  /// small sl.
  static AsymmetricNormal fit(const VecX& samples) {
    const Eigen::Index n = samples.size();
    if (n < 3)
      nlosloc::detail::throw_invalid_argument(
          std::string(kName) + "::fit: samples: expected at least 3 values, got " + std::to_string(n));
    if (!samples.allFinite())
      nlosloc::detail::throw_invalid_argument(std::string(kName) +
                                              "::fit: samples: expected finite values (no NaN or inf)");
    std::vector<double> x(samples.data(), samples.data() + n);
    std::sort(x.begin(), x.end());
    if (!(x.front() < x.back()))
      nlosloc::detail::throw_invalid_argument(
          std::string(kName) + "::fit: samples: expected a nonzero spread, got all values equal to " +
          detail::fmt(x.front()));
    // Centre for the prefix sums (less cancellation in Q - 2 m P + k m^2).
    const double c = 0.5 * (x.front() + x.back());
    for (auto& v : x) v -= c;
    const auto un = static_cast<std::size_t>(n);
    std::vector<double> p1(un + 1, 0.0), p2(un + 1, 0.0);  // prefix sums of x and x^2
    for (std::size_t i = 0; i < un; ++i) {
      p1[i + 1] = p1[i] + x[i];
      p2[i + 1] = p2[i] + x[i] * x[i];
    }
    // a + b for mode m with the first k sorted samples on the left (valid for m in [x[k-1], x[k]]).
    auto g = [&](double m, std::size_t k) {
      const double kk = static_cast<double>(k), kr = static_cast<double>(un - k);
      const double sl = std::max(0.0, p2[k] - 2.0 * m * p1[k] + kk * m * m);
      const double sr = std::max(0.0, (p2[un] - p2[k]) - 2.0 * m * (p1[un] - p1[k]) + kr * m * m);
      if (!(sl > 0.0) || !(sr > 0.0)) return detail::kInf;
      return std::cbrt(sl) + std::cbrt(sr);
    };
    std::size_t best = 0;
    double gbest = detail::kInf;
    for (std::size_t j = 1; j + 1 < un; ++j) {
      const double gj = g(x[j], j);
      if (gj < gbest) {
        gbest = gj;
        best = j;
      }
    }
    double mbest = 0.0;
    if (std::isfinite(gbest)) {
      mbest = x[best];
      // Golden section on [x[k-1], x[k]] for the splits k = best and best + 1.
      for (std::size_t k : {best, best + 1}) {
        double lo = x[k - 1], hi = x[k];
        const double r = 0.5 * (std::sqrt(5.0) - 1.0);
        double m1 = hi - r * (hi - lo), m2 = lo + r * (hi - lo);
        double g1 = g(m1, k), g2 = g(m2, k);
        for (int it = 0; it < 100 && hi - lo > 1e-12 * (std::abs(lo) + std::abs(hi) + 1e-300); ++it) {
          if (g1 <= g2) {
            hi = m2;
            m2 = m1;
            g2 = g1;
            m1 = hi - r * (hi - lo);
            g1 = g(m1, k);
          } else {
            lo = m1;
            m1 = m2;
            g1 = g2;
            m2 = lo + r * (hi - lo);
            g2 = g(m2, k);
          }
        }
        if (g1 < gbest) {
          gbest = g1;
          mbest = m1;
        }
        if (g2 < gbest) {
          gbest = g2;
          mbest = m2;
        }
      }
    } else {
      // Only two distinct values at the ends: the mode sits midway between them.
      mbest = 0.5 * (x.front() + x.back());
    }
    // Recompute the sums directly at the chosen mode.
    double sl = 0.0, sr = 0.0;
    for (double v : x) (v < mbest ? sl : sr) += (v - mbest) * (v - mbest);
    const double a = std::cbrt(sl), b = std::cbrt(sr);
    const double s = std::sqrt((a + b) / static_cast<double>(n));
    const double sigma_l = a * s, sigma_r = b * s;
    if (!(sigma_l > 0.0) || !(sigma_r > 0.0))
      nlosloc::detail::throw_invalid_argument(
          std::string(kName) +
          "::fit: samples: the fit degenerated (a zero sigma); need values on both "
          "sides of the mode");
    return AsymmetricNormal(mbest + c, sigma_l, sigma_r);
  }
  /// Mode.
  double mode() const { return mode_; }
  /// Standard deviation left of the mode.
  double sigma_left() const { return sl_; }
  /// Standard deviation right of the mode.
  double sigma_right() const { return sr_; }
  /// mode + sqrt(2/pi)(sr - sl) (Wallis 2014 eq. 2).
  double mean() const { return mode_ + std::sqrt(2.0 / kPi) * (sr_ - sl_); }
  /// (1 - 2/pi)(sr - sl)^2 + sl sr (Wallis 2014 eq. 3).
  double variance() const { return (1.0 - 2.0 / kPi) * (sr_ - sl_) * (sr_ - sl_) + sl_ * sr_; }
  /// log 2 - log(sqrt(2 pi)(sl + sr)) - (x - mode)^2/(2 s^2) (Cong & Zhuang 2005).
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    const double z = (x - mode_) / (x < mode_ ? sl_ : sr_);
    return std::log(2.0 / (sl_ + sr_)) - detail::kLogSqrt2Pi - 0.5 * z * z;
  }
  /// 2 sl/(sl + sr) Phi((x - mode)/sl) left of the mode, 1 - 2 sr/(sl + sr) Q((x - mode)/sr) right of it.
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    if (x <= mode_) return 2.0 * sl_ / (sl_ + sr_) * detail::phi_cdf((x - mode_) / sl_);
    return 1.0 - 2.0 * sr_ / (sl_ + sr_) * detail::phi_sf((x - mode_) / sr_);
  }
  /// Picks the side with probability sl/(sl + sr), then a half-normal deviation of that side's sigma.
  double sample(Rng& rng) const {
    const double side = rng.uniform();
    const double h = std::abs(rng.normal());
    return side * (sl_ + sr_) < sl_ ? mode_ - sl_ * h : mode_ + sr_ * h;
  }

 private:
  friend class detail::DistributionBase<AsymmetricNormal>;
  double quantile_lower_(double p) const {
    const double pl = sl_ / (sl_ + sr_);  // mass left of the mode
    if (p <= pl) return mode_ + sl_ * detail::phi_inv(p * (sl_ + sr_) / (2.0 * sl_));
    return mode_ + sr_ * detail::phi_inv_upper((1.0 - p) * (sl_ + sr_) / (2.0 * sr_));
  }
  double quantile_upper_(double q) const {
    const double pr = sr_ / (sl_ + sr_);  // mass right of the mode
    if (q <= pr) return mode_ + sr_ * detail::phi_inv_upper(q * (sl_ + sr_) / (2.0 * sr_));
    return mode_ + sl_ * detail::phi_inv((1.0 - q) * (sl_ + sr_) / (2.0 * sl_));
  }
  double mode_, sl_, sr_;
};

/// Beta(a, b) on [0, 1]: pdf x^(a-1)(1-x)^(b-1)/B(a, b); mean a/(a+b), variance ab/((a+b)^2(a+b+1)).
/// Quality statistics of Grisales Fig. 2 (LOS Beta(4, 1.5), soft NLOS Beta(3, 1.5), hard NLOS Beta(1.5, 4))
/// and of the H1/H2 scenarios.
class Beta : public detail::DistributionBase<Beta> {
 public:
  static constexpr const char* kName = "Beta";
  /// a > 0, b > 0.
  Beta(double a, double b) : a_(a), b_(b) {
    detail::check_positive(kName, "a", a);
    detail::check_positive(kName, "b", b);
    const double bab = boost::math::beta(a, b, detail::Policy());
    log_beta_ = bab >= std::numeric_limits<double>::min() && std::isfinite(bab)
                    ? std::log(bab)
                    : boost::math::lgamma(a, detail::Policy()) + boost::math::lgamma(b, detail::Policy()) -
                          boost::math::lgamma(a + b, detail::Policy());
  }
  /// First shape parameter a.
  double a() const { return a_; }
  /// Second shape parameter b.
  double b() const { return b_; }
  /// a/(a + b).
  double mean() const { return a_ / (a_ + b_); }
  /// ab/((a + b)^2 (a + b + 1)).
  double variance() const { return a_ * b_ / ((a_ + b_) * (a_ + b_) * (a_ + b_ + 1.0)); }
  /// (a-1) log x + (b-1) log1p(-x) - log B(a, b) on [0, 1] (a term with exponent 0 counts 0), -inf outside.
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    if (x < 0.0 || x > 1.0) return -detail::kInf;
    return xlogy(a_ - 1.0, x) + xlogy(b_ - 1.0, 1.0 - x, -x) - log_beta_;
  }
  /// Regularized incomplete beta I_x(a, b) (Boost ibeta).
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return 1.0;
    const double r = boost::math::ibeta(a_, b_, x, detail::Policy());
    // Near the underflow Boost's value loses its accuracy (or is 0): the series in logs instead.
    return r < 1e-250 && x <= 0.5 ? std::exp(log_ibeta_lower(x, a_, b_, log_beta_)) : r;
  }

 private:
  friend class detail::DistributionBase<Beta>;
  /// c * log(y) with 0 * log(0) = 0; log1p(m) used for y = 1 + m when m is given.
  static double xlogy(double c, double y, double m = detail::kNaN) {
    if (c == 0.0) return 0.0;
    return c * (std::isnan(m) ? std::log(y) : std::log1p(m));
  }
  boost::math::beta_distribution<double, detail::Policy> dist() const {
    return boost::math::beta_distribution<double, detail::Policy>(a_, b_);
  }
  /// Root y of I_y(a, b) = p in the far tail, or NaN when it is not there: I_y(a, b) = y^a / (a B(a, b))
  /// (1 + O((a + b) y)) (leading term of DLMF 8.17.8), so y = (p a B(a, b))^(1/a) is exact to rounding
  /// once (a + b + 1) y < 1e-16. Boost's inversion fails there (below p ~ 1e-100: an evaluation error
  /// thrown despite the policy, or a root off by a factor 2).
  static double tail_root(double p, double a, double b, double log_beta) {
    const double y = std::exp((std::log(p) + std::log(a) + log_beta) / a);
    return y * (a + b + 1.0) < 1e-16 ? y : detail::kNaN;
  }
  /// log I_y(a, b) for y <= 1/2 from DLMF 8.17.8: I_y(a, b) = y^a (1 - y)^b / (a B(a, b)) F(a + b, 1; a + 1;
  /// y), the series F = sum_n t_n with t_0 = 1, t_(n+1) = t_n y (a + b + n)/(a + 1 + n). In logs, so it holds
  /// where I_y underflows or nears it; Boost's ibeta loses its accuracy below about 1e-280 (and returns 0
  /// for Beta(300, 20) at 1e-295).
  static double log_ibeta_lower(double y, double a, double b, double log_beta) {
    double term = 1.0, sum = 1.0;
    for (int n = 0; n < 2000 && term > 1e-17 * sum; ++n) {
      term *= y * (a + b + n) / (a + 1.0 + n);
      sum += term;
    }
    return a * std::log(y) + b * std::log1p(-y) - std::log(a) - log_beta + std::log(sum);
  }
  /// Root y of I_y(a, b) = p: the tail's closed form, else Boost's inversion. Below p = 1e-100 Boost's root
  /// can be off by up to 3e-4 relative (I_y/p - 1 up to 2% for Beta(50, 20) at p = 1e-300), so there it is
  /// refined by Newton's method on log I_y(a, b) = log p (log_ibeta_lower) in log y, where the curve is
  /// nearly a line of slope a (I_y ~ y^a): t <- t - (log I - log p) I / (y pdf(y)).
  static double lower_root(double p, double a, double b, double log_beta) {
    const double tail = tail_root(p, a, b, log_beta);
    if (!std::isnan(tail)) return tail;
    double y = boost::math::quantile(boost::math::beta_distribution<double, detail::Policy>(a, b), p);
    if (!(p < 1e-100) || !(y > 0.0) || !(y <= 0.5)) return y;
    const double log_p = std::log(p);
    for (int it = 0; it < 8; ++it) {
      const double log_i = log_ibeta_lower(y, a, b, log_beta);
      const double log_y_pdf = a * std::log(y) + (b - 1.0) * std::log1p(-y) - log_beta;  // log(y pdf(y))
      const double yn = y * std::exp(-(log_i - log_p) * std::exp(log_i - log_y_pdf));
      if (!(yn > 0.0 && yn <= 0.5)) break;
      const bool done = std::abs(yn - y) <= 1e-15 * y;
      y = yn;
      if (done) break;
    }
    return y;
  }
  double quantile_lower_(double p) const {
    if (p <= 0.0) return 0.0;
    return lower_root(p, a_, b_, log_beta_);
  }
  double quantile_upper_(double q) const {
    if (q <= 0.0) return 1.0;
    // 1 - I_x(a, b) = I_(1-x)(b, a): the root y = 1 - x of the mirrored distribution
    if (!(q < 1e-100) && std::isnan(tail_root(q, b_, a_, log_beta_)))
      return boost::math::quantile(boost::math::complement(dist(), q));
    return 1.0 - lower_root(q, b_, a_, log_beta_);
  }
  double a_, b_, log_beta_ = 0.0;
};

/// Empirical distribution: Gaussian kernel density of samples s_1..s_n with Silverman's bandwidth exactly as
/// scipy.stats.gaussian_kde(samples, bw_method="silverman") in 1-D: h = std(s, ddof=1) (3n/4)^(-1/5)
/// (Silverman 1986, Density Estimation, eq. 3.28). pdf = mean_i N(x; s_i, h^2), cdf = mean_i Phi((x -
/// s_i)/h), quantile by safeguarded Newton to 1e-12 relative. mean = sample mean; variance = var(s, ddof=0) +
/// h^2, the variance of the smoothed density (not the sample variance). sample = a random s_i + h * normal.
class Empirical : public detail::DistributionBase<Empirical> {
 public:
  static constexpr const char* kName = "Empirical";
  /// samples: n >= 2 finite values, not all equal.
  explicit Empirical(const VecX& samples) : s_(samples) {
    const Eigen::Index n = samples.size();
    if (n < 2)
      nlosloc::detail::throw_invalid_argument(
          std::string(kName) + ": samples: expected at least 2 values, got " + std::to_string(n));
    if (!samples.allFinite())
      nlosloc::detail::throw_invalid_argument(std::string(kName) +
                                              ": samples: expected finite values (no NaN or inf)");
    std::sort(s_.data(), s_.data() + n);
    const double dn = static_cast<double>(n);
    mean_ = s_.mean();
    const double ss = (s_.array() - mean_).square().sum();
    const double sd1 = std::sqrt(ss / (dn - 1.0));
    if (!(sd1 > 0.0))
      nlosloc::detail::throw_invalid_argument(
          std::string(kName) + ": samples: expected a nonzero spread (std > 0), got all values equal to " +
          detail::fmt(s_[0]));
    h_ = sd1 * std::pow(dn * 0.75, -0.2);  // scipy silverman_factor, d = 1
    var_ = ss / dn + h_ * h_;
    // finite samples whose spread overflows (e.g. +-1e200) gave h = inf and a degenerate density
    if (!std::isfinite(mean_) || !std::isfinite(var_))
      nlosloc::detail::throw_invalid_argument(std::string(kName) +
                                              ": samples: spread too large (its variance overflows)");
  }
  /// The samples, sorted ascending.
  const VecX& samples() const { return s_; }
  /// Number of samples.
  Eigen::Index size() const { return s_.size(); }
  /// Kernel bandwidth h (standard deviation of each Gaussian kernel).
  double bandwidth() const { return h_; }
  /// Sample mean.
  double mean() const { return mean_; }
  /// var(samples, ddof=0) + h^2.
  double variance() const { return var_; }
  /// log mean_i N(x; s_i, h^2), by log-sum-exp.
  double log_pdf(double x) const {
    if (std::isnan(x)) return x;
    if (std::isinf(x)) return -detail::kInf;
    double mx = -detail::kInf;
    for (Eigen::Index i = 0; i < s_.size(); ++i) {
      const double z = (x - s_[i]) / h_;
      mx = std::max(mx, -0.5 * z * z);
    }
    if (mx == -detail::kInf) return mx;  // z^2 overflowed for every sample: density 0 (not -inf - -inf)
    double acc = 0.0;
    for (Eigen::Index i = 0; i < s_.size(); ++i) {
      const double z = (x - s_[i]) / h_;
      acc += std::exp(-0.5 * z * z - mx);
    }
    return mx + std::log(acc / static_cast<double>(s_.size())) - std::log(h_) - detail::kLogSqrt2Pi;
  }
  /// mean_i Phi((x - s_i)/h) (scipy's integrate_box_1d(-inf, x)).
  double cdf(double x) const {
    if (std::isnan(x)) return x;
    double acc = 0.0;
    for (Eigen::Index i = 0; i < s_.size(); ++i) acc += detail::phi_cdf((x - s_[i]) / h_);
    return std::min(1.0, acc / static_cast<double>(s_.size()));
  }
  /// A uniformly chosen sample plus h times a standard normal.
  double sample(Rng& rng) const {
    const auto i = static_cast<Eigen::Index>(rng.below(static_cast<std::uint64_t>(s_.size())));
    return s_[i] + h_ * rng.normal();
  }

 private:
  friend class detail::DistributionBase<Empirical>;
  double sf(double x) const {
    double acc = 0.0;
    for (Eigen::Index i = 0; i < s_.size(); ++i) acc += detail::phi_sf((x - s_[i]) / h_);
    return acc / static_cast<double>(s_.size());
  }
  // Bracket: Phi((x - max)/h) <= cdf(x) <= Phi((x - min)/h), so the root of cdf = p lies in
  // [min + h Phi^-1(p), max + h Phi^-1(p)]; the same with the upper tail for sf = q.
  double quantile_lower_(double p) const {
    if (p <= 0.0) return -detail::kInf;
    const double zp = detail::phi_inv(p);
    const double lo = s_[0] + h_ * zp, hi = s_[s_.size() - 1] + h_ * zp;
    const double x0 = mean_ + std::sqrt(var_) * zp;
    return detail::solve_increasing([&](double x) { return cdf(x) - p; }, [&](double x) { return pdf(x); },
                                    lo, hi, x0, h_);
  }
  double quantile_upper_(double q) const {
    if (q <= 0.0) return detail::kInf;
    const double zq = detail::phi_inv_upper(q);
    const double lo = s_[0] + h_ * zq, hi = s_[s_.size() - 1] + h_ * zq;
    const double x0 = mean_ + std::sqrt(var_) * zq;
    return detail::solve_increasing([&](double x) { return q - sf(x); }, [&](double x) { return pdf(x); }, lo,
                                    hi, x0, h_);
  }
  VecX s_;
  double h_ = 0.0, mean_ = 0.0, var_ = 0.0;
};

/// Type-erased noise distribution (a std::variant of the classes above), implicitly constructible from each.
/// The filters call mean(), variance(), from_standard_normal(u) and log_pdf(x) on it. Default: Normal(0, 1).
class Distribution {
 public:
  using Variant = std::variant<Normal, Rayleigh, Exponential, Gev, TruncatedNormal, ShiftedNormal,
                               AsymmetricNormal, Beta, Empirical>;

  /// Standard normal N(0, 1).
  Distribution() : v_(Normal(0.0, 1.0)) {}
  /// From any of the distribution classes (implicit).
  template <class T, class = std::enable_if_t<std::is_constructible_v<Variant, T&&> &&
                                              !std::is_same_v<std::decay_t<T>, Distribution>>>
  Distribution(T&& d) : v_(std::forward<T>(d)) {}  // NOLINT(google-explicit-constructor)

  double log_pdf(double x) const {
    return visit([x](const auto& d) { return d.log_pdf(x); });
  }
  double pdf(double x) const {
    return visit([x](const auto& d) { return d.pdf(x); });
  }
  double cdf(double x) const {
    return visit([x](const auto& d) { return d.cdf(x); });
  }
  double quantile(double p) const {
    return visit([p](const auto& d) { return d.quantile(p); });
  }
  double mean() const {
    return visit([](const auto& d) { return d.mean(); });
  }
  double variance() const {
    return visit([](const auto& d) { return d.variance(); });
  }
  double sample(Rng& rng) const {
    return std::visit([&rng](const auto& d) { return d.sample(rng); }, v_);
  }
  double from_standard_normal(double u) const {
    return visit([u](const auto& d) { return d.from_standard_normal(u); });
  }
  const char* name() const {
    return std::visit([](const auto& d) { return d.name(); }, v_);
  }

  /// True when the held distribution is a T.
  template <class T>
  bool holds() const {
    return std::holds_alternative<T>(v_);
  }
  /// The held T; throws std::bad_variant_access when it holds another type.
  template <class T>
  const T& get() const {
    return std::get<T>(v_);
  }
  /// The underlying variant (for std::visit).
  const auto& variant() const { return v_; }

 private:
  template <class F>
  double visit(F&& f) const {
    return std::visit(std::forward<F>(f), v_);
  }
  Variant v_;
};

}  // namespace nlosloc::noise
