// Tests of nlosloc/models/noise.hpp: hand-computed values, quantile round trips, the Gaussian-quantile
// transform, moments against numeric integration and against sample moments, argument checking.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "nlosloc/models/noise.hpp"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using nlosloc::Rng;
using nlosloc::VecX;
using namespace nlosloc::noise;

// Every member of every distribution compiled (Sophus habit): explicit instantiation of the shared base.
namespace nlosloc::noise::detail {
template class DistributionBase<Normal>;
template class DistributionBase<Rayleigh>;
template class DistributionBase<Exponential>;
template class DistributionBase<Gev>;
template class DistributionBase<TruncatedNormal>;
template class DistributionBase<ShiftedNormal>;
template class DistributionBase<AsymmetricNormal>;
template class DistributionBase<Beta>;
template class DistributionBase<Empirical>;
}  // namespace nlosloc::noise::detail

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

VecX kde_samples() {
  VecX s(12);
  s << 0.3, 1.7, 2.2, 2.9, 3.1, 3.3, 4.0, 4.8, 5.5, 7.2, 9.0, 12.5;
  return s;
}

// A spread scale of d for tolerances (std, or a quantile range when the variance is infinite).
template <class D>
double spread(const D& d) {
  const double v = d.variance();
  return std::isfinite(v) ? std::sqrt(v) : d.quantile(0.75) - d.quantile(0.25);
}

// The property suite every distribution passes (a template, reused per model).
template <class D>
void check_common(const D& d) {
  INFO(d.name());
  const double sc = spread(d);
  // quantile(cdf(x)) == x on points across the body of the distribution.
  for (double p : {1e-6, 1e-3, 0.02, 0.2, 0.5, 0.8, 0.98, 0.999}) {
    const double x = d.quantile(p);
    // Relative 1e-9, plus the cdf change over a few ulps of x (x may sit next to a bound far from 0).
    CHECK_THAT(d.cdf(x), WithinAbs(p, 1e-9 * p + 4.0 * d.pdf(x) * std::numeric_limits<double>::epsilon() *
                                                     std::abs(x)));
    CHECK_THAT(d.quantile(d.cdf(x)), WithinAbs(x, 1e-9 * (std::abs(x) + sc)));
  }
  // from_standard_normal(0) is the median; its tails are monotone (distinct up to u = 8 where the support is
  // unbounded or its bound is 0; next to a bound b != 0 the offset can be below the spacing of doubles at b).
  CHECK_THAT(d.from_standard_normal(0.0),
             WithinAbs(d.quantile(0.5), 1e-12 * (std::abs(d.quantile(0.5)) + sc)));
  CHECK_THAT(d.from_standard_normal(1.0), WithinAbs(d.quantile(0.8413447460685429), 1e-9 * sc));
  CHECK(d.from_standard_normal(7.9) <= d.from_standard_normal(8.0));
  CHECK(d.from_standard_normal(-8.0) <= d.from_standard_normal(-7.9));
  CHECK(d.from_standard_normal(5.0) < d.from_standard_normal(8.0));
  CHECK(d.from_standard_normal(-8.0) < d.from_standard_normal(-5.0));
  CHECK(d.from_standard_normal(-8.0) <= d.quantile(1e-12));
  CHECK(d.from_standard_normal(8.0) >= d.quantile(1.0 - 1e-12));
  CHECK(std::isnan(d.from_standard_normal(kNaN)));
  // Conventions at the edges.
  CHECK(std::isnan(d.log_pdf(kNaN)));
  CHECK(std::isnan(d.cdf(kNaN)));
  CHECK(d.log_pdf(kInf) == -kInf);
  CHECK(d.log_pdf(-kInf) == -kInf);
  CHECK(d.cdf(-kInf) == 0.0);
  CHECK(d.cdf(kInf) == 1.0);
  CHECK_THAT(d.pdf(d.quantile(0.3)), WithinRel(std::exp(d.log_pdf(d.quantile(0.3))), 1e-15));
  for (double p : {0.0, 1.0, -0.1, 1.5, kNaN}) CHECK_THROWS_AS(d.quantile(p), std::invalid_argument);
}

// The transform keeps the tails apart up to |u| = 8 (supports unbounded or bounded at 0 / 1).
template <class D>
void check_distinct_tails(const D& d) {
  INFO(d.name());
  CHECK(d.from_standard_normal(7.9) < d.from_standard_normal(8.0));
  CHECK(d.from_standard_normal(-8.0) < d.from_standard_normal(-7.9));
}

// Trapezoid integration of the pdf on a fine grid between the 1e-11 and 1 - 1e-11 quantiles.
template <class D>
void check_moments_by_integration(const D& d, double rel = 1e-6) {
  INFO(d.name());
  const double lo = d.quantile(1e-11), hi = d.quantile(1.0 - 1e-11);
  const int n = 400000;
  const double dx = (hi - lo) / n;
  double m0 = 0.0, m1 = 0.0;
  std::vector<double> f(n + 1), x(n + 1);
  for (int i = 0; i <= n; ++i) {
    x[i] = lo + dx * i;
    f[i] = d.pdf(x[i]) * ((i == 0 || i == n) ? 0.5 : 1.0) * dx;
    m0 += f[i];
    m1 += x[i] * f[i];
  }
  double m2 = 0.0;
  for (int i = 0; i <= n; ++i) m2 += (x[i] - m1) * (x[i] - m1) * f[i];
  CHECK_THAT(m0, WithinAbs(1.0, 1e-7));
  CHECK_THAT(m1, WithinAbs(d.mean(), rel * spread(d)));
  CHECK_THAT(m2, WithinRel(d.variance(), rel));
}

// Mean and variance of 200000 draws within 5 standard errors (the variance's from the sample 4th moment).
template <class D>
void check_sample_moments(const D& d, std::uint64_t seed) {
  INFO(d.name());
  Rng rng(seed);
  const int n = 200000;
  std::vector<double> x(n);
  double m = 0.0;
  for (auto& v : x) {
    v = d.sample(rng);
    m += v;
  }
  m /= n;
  double m2 = 0.0, m4 = 0.0;
  for (double v : x) {
    const double c = (v - m) * (v - m);
    m2 += c;
    m4 += c * c;
  }
  m2 /= n;
  m4 /= n;
  CHECK_THAT(m, WithinAbs(d.mean(), 5.0 * std::sqrt(d.variance() / n)));
  CHECK_THAT(m2, WithinAbs(d.variance(), 5.0 * std::sqrt((m4 - m2 * m2) / n)));
}

}  // namespace

TEST_CASE("Normal: values, transform, moments", "[noise]") {
  const Normal d(1.0, 2.0);
  CHECK(std::string(d.name()) == "Normal");
  CHECK(d.mean() == 1.0);
  CHECK(d.stddev() == 2.0);
  CHECK(d.variance() == 4.0);
  // log N(2; 1, 4) = -0.5 (1/2)^2 - log 2 - log sqrt(2 pi) = -0.125 - 0.6931471805599453 - 0.9189385332046727
  CHECK_THAT(d.log_pdf(2.0), WithinRel(-1.7370857137646180, 1e-14));
  CHECK_THAT(d.cdf(1.0), WithinAbs(0.5, 1e-16));
  CHECK_THAT(d.cdf(3.0), WithinRel(0.8413447460685429, 1e-14));                        // Phi(1)
  CHECK_THAT(d.cdf(-19.0), WithinRel(0.5 * std::erfc(10.0 / std::sqrt(2.0)), 1e-13));  // Phi(-10)
  CHECK_THAT(d.quantile(0.975), WithinRel(1.0 + 2.0 * 1.959963984540054, 1e-14));
  // Exactly mean + std u, even far in the tails.
  CHECK(d.from_standard_normal(8.0) == 1.0 + 2.0 * 8.0);
  CHECK(d.from_standard_normal(-30.0) == 1.0 - 60.0);
  check_common(d);
  check_moments_by_integration(d);
  check_sample_moments(d, 1);
}

TEST_CASE("Rayleigh: values, from_variance, moments", "[noise]") {
  const Rayleigh d(2.0);
  CHECK(d.scale() == 2.0);
  // pdf(1) = 1/s^2 exp(-1/(2 s^2)) = 0.25 exp(-0.125) = 0.25 * 0.8824969025845955
  CHECK_THAT(d.pdf(1.0), WithinRel(0.22062422564614886, 1e-14));
  CHECK_THAT(d.cdf(2.0), WithinRel(1.0 - std::exp(-0.5), 1e-14));
  // median s sqrt(2 ln 2)
  CHECK_THAT(d.quantile(0.5), WithinRel(2.3548200450309493, 1e-14));
  CHECK_THAT(d.mean(), WithinRel(2.0 * std::sqrt(nlosloc::kPi / 2.0), 1e-15));
  CHECK_THAT(d.variance(), WithinRel(2.0 * (4.0 - nlosloc::kPi), 1e-15));
  CHECK(d.log_pdf(0.0) == -kInf);
  CHECK(d.log_pdf(-1.0) == -kInf);
  CHECK(d.cdf(-1.0) == 0.0);
  // Huerta Table VIII: NLOS TOA variance 2000 m^2 -> scale sqrt(4000/(4 - pi)).
  const Rayleigh h = Rayleigh::from_variance(2000.0);
  CHECK_THAT(h.scale(), WithinRel(68.26267183699659, 1e-14));
  CHECK_THAT(h.variance(), WithinRel(2000.0, 1e-14));
  // Upper tail from the complement: F^-1(1 - Q(8)) = s sqrt(-2 log Q(8)), Q(8) = 6.22096057427178e-16.
  CHECK_THAT(d.from_standard_normal(8.0),
             WithinRel(2.0 * std::sqrt(-2.0 * std::log(6.22096057427178e-16)), 1e-12));
  check_distinct_tails(d);
  check_common(d);
  check_moments_by_integration(d);
  check_sample_moments(d, 2);
}

TEST_CASE("Exponential: values, moments", "[noise]") {
  const Exponential d(0.5);
  // pdf(1) = 2 exp(-2)
  CHECK_THAT(d.pdf(1.0), WithinRel(0.2706705664732254, 1e-14));
  CHECK_THAT(d.log_pdf(0.0), WithinRel(std::log(2.0), 1e-15));
  CHECK(d.log_pdf(-1e-300) == -kInf);
  CHECK_THAT(d.cdf(1.0), WithinRel(0.8646647167633873, 1e-14));
  CHECK_THAT(d.quantile(0.5), WithinRel(0.5 * std::log(2.0), 1e-14));
  CHECK(d.mean() == 0.5);
  CHECK(d.variance() == 0.25);
  // -m log Q(8) with Q(8) = 6.22096057427178e-16 (scipy.special.ndtr(-8)).
  CHECK_THAT(d.from_standard_normal(8.0), WithinRel(17.50671857995728, 1e-12));
  // Tiny lower-tail probabilities keep relative accuracy: F^-1(p) ~ m p.
  CHECK_THAT(d.quantile(1e-300), WithinRel(0.5e-300, 1e-12));
  check_distinct_tails(d);
  check_common(d);
  check_moments_by_integration(d);
  check_sample_moments(d, 3);
}

TEST_CASE("Gev: Grisales hard NLOS values, Gumbel limit, moments", "[noise]") {
  const Gev d(0.4, 8.5, 4.25);  // Grisales Sec. 5, in ns
  CHECK(d.shape() == 0.4);
  CHECK(d.loc() == 8.5);
  CHECK(d.scale() == 4.25);
  // x = mu + sigma: t = 1.4^(-1/0.4) = 0.4312011503716922, cdf = exp(-t), pdf = t^1.4 exp(-t)/sigma
  CHECK_THAT(d.cdf(12.75), WithinRel(0.6497282045595423, 1e-13));
  CHECK_THAT(d.pdf(12.75), WithinRel(0.04708631079579981, 1e-13));
  // median mu + sigma ((ln 2)^(-k) - 1)/k
  CHECK_THAT(d.quantile(0.5), WithinRel(10.177652420124744, 1e-13));
  // mean mu + sigma (Gamma(0.6) - 1)/0.4, variance sigma^2 (Gamma(0.2) - Gamma(0.6)^2)/0.16
  CHECK_THAT(d.mean(), WithinRel(13.69766764363618, 1e-13));
  CHECK_THAT(d.variance(), WithinRel(267.90640456389366, 1e-12));
  // Support starts at mu - sigma/k = -2.125 for k > 0.
  CHECK(d.log_pdf(-2.2) == -kInf);
  CHECK(d.cdf(-2.2) == 0.0);
  CHECK_THAT(d.from_standard_normal(-40.0), WithinRel(-2.125, 1e-12));
  // Heavy tails: infinite moments.
  CHECK(Gev(0.6, 0.0, 1.0).variance() == kInf);
  CHECK(std::isfinite(Gev(0.6, 0.0, 1.0).mean()));
  CHECK(Gev(1.0, 0.0, 1.0).mean() == kInf);
  check_distinct_tails(d);
  check_common(d);
  check_sample_moments(Gev(0.1, 8.5, 4.25), 4);  // k < 1/4: finite fourth moment
  check_moments_by_integration(Gev(0.1, 8.5, 4.25), 2e-6);
  check_moments_by_integration(Gev(-0.3, 1.0, 2.0));

  SECTION("k = 0 is the Gumbel distribution and small k is continuous") {
    const Gev g(0.0, 1.0, 2.0);
    CHECK_THAT(g.cdf(1.0), WithinRel(std::exp(-1.0), 1e-15));
    CHECK_THAT(g.mean(), WithinRel(1.0 + 2.0 * 0.5772156649015329, 1e-15));
    CHECK_THAT(g.variance(), WithinRel(4.0 * nlosloc::kPi * nlosloc::kPi / 6.0, 1e-15));
    // pdf(mu) = exp(-1)/sigma
    CHECK_THAT(g.pdf(1.0), WithinRel(std::exp(-1.0) / 2.0, 1e-15));
    check_common(g);
    check_sample_moments(g, 5);
    check_moments_by_integration(g);
    for (double k : {1e-9, -1e-9}) {
      const Gev e(k, 1.0, 2.0);
      CHECK_THAT(e.variance(), WithinRel(g.variance(), 1e-7));
      CHECK_THAT(e.mean(), WithinRel(g.mean(), 1e-7));
      CHECK_THAT(e.cdf(3.0), WithinRel(g.cdf(3.0), 1e-7));
      CHECK_THAT(e.quantile(0.9), WithinRel(g.quantile(0.9), 1e-7));
    }
    // Series / lgamma switch at |k| = 0.05 is continuous.
    CHECK_THAT(Gev(0.05 - 1e-9, 0.0, 1.0).variance(), WithinRel(Gev(0.05 + 1e-9, 0.0, 1.0).variance(), 1e-7));
    CHECK_THAT(Gev(0.01, 0.0, 1.0).variance(),
               WithinRel(1.6891637935455226, 1e-9));  // scipy genextreme(c=-0.01)
  }
}

TEST_CASE("TruncatedNormal: half normal, Giremus prior, far tail interval", "[noise]") {
  const TruncatedNormal half(0.0, 1.0, 0.0, kInf);
  // half normal: pdf(0) = 2 phi(0) = sqrt(2/pi), mean sqrt(2/pi), variance 1 - 2/pi
  CHECK_THAT(half.pdf(0.0), WithinRel(0.7978845608028654, 1e-14));
  CHECK_THAT(half.mean(), WithinRel(0.7978845608028654, 1e-14));
  CHECK_THAT(half.variance(), WithinRel(1.0 - 2.0 / nlosloc::kPi, 1e-14));
  CHECK(half.log_pdf(-1e-12) == -kInf);
  CHECK(half.cdf(-1.0) == 0.0);
  CHECK_THAT(half.cdf(1.0), WithinRel(2.0 * 0.8413447460685429 - 1.0, 1e-14));
  check_common(half);
  check_distinct_tails(half);
  check_sample_moments(half, 6);

  // Giremus & Grolleau Sec. 5: N(2000, 2000^2/9) truncated to x > 0, i.e. alpha = -3 (scipy truncnorm).
  const TruncatedNormal g(2000.0, 2000.0 / 3.0, 0.0, kInf);
  CHECK_THAT(g.mean(), WithinRel(2002.9585593614172, 1e-13));
  CHECK_THAT(g.variance(), WithinRel(438518.57264811517, 1e-12));
  CHECK(g.lower() == 0.0);
  CHECK(g.upper() == kInf);
  check_common(g);
  check_moments_by_integration(g);
  check_sample_moments(g, 7);

  // A two-sided interval far in the right tail: [mu + 8 sigma, mu + 9 sigma].
  const TruncatedNormal t(0.0, 1.0, 8.0, 9.0);
  CHECK(t.mean() > 8.0);
  CHECK(t.mean() < 8.2);
  CHECK_THAT(t.cdf(8.5),
             WithinRel((0.5 * std::erfc(8.0 / std::sqrt(2.0)) - 0.5 * std::erfc(8.5 / std::sqrt(2.0))) /
                           (0.5 * std::erfc(8.0 / std::sqrt(2.0)) - 0.5 * std::erfc(9.0 / std::sqrt(2.0))),
                       1e-12));
  check_common(t);
  check_moments_by_integration(t);
  // Next to a bound away from 0 the cdf keeps its relative accuracy (offset x - lower used as is):
  // x = -1 + 2^-33 (exact): the mass of [-1, -1 + 2^-34] in standard units is phi(-1) 2^-34 (1 + O(2^-34));
  // Z = Phi(1.5) - Phi(-1).
  const TruncatedNormal two(1.0, 2.0, -1.0, 4.0);
  const double phi1 = std::exp(-0.5) / std::sqrt(2.0 * nlosloc::kPi);
  const double z_two = 0.5 * std::erfc(-1.5 / std::sqrt(2.0)) - 0.5 * std::erfc(1.0 / std::sqrt(2.0));
  const double off = std::ldexp(1.0, -33);
  CHECK_THAT(two.cdf(-1.0 + off), WithinRel(phi1 * 0.5 * off / z_two, 1e-9));
  CHECK_THAT(two.quantile(phi1 * 0.5 * off / z_two) + 1.0, WithinRel(off, 1e-5));  // x + 1 resolves to ~1e-16
  check_common(two);
  check_moments_by_integration(two);
  // Left-tail interval, lower infinite.
  const TruncatedNormal l(0.0, 1.0, -kInf, -6.0);
  check_common(l);
  check_moments_by_integration(l);
}

namespace {
/// Variance of N(0, 1) on [a, inf) from Laplace's continued fraction of the Mills ratio R = 1/(a + T_1),
/// T_k = k/(a + T_(k+1)): 1 + a/R - 1/R^2 = (T_2 - T_1)/(a + T_2), free of JKB eq. 13.135's cancellation.
double mills_variance(double a) {
  double t = 0.0, t1 = 0.0, t2 = 0.0;
  for (int k = 4000; k >= 1; --k) {
    t = k / (a + t);
    if (k == 2) t2 = t;
    if (k == 1) t1 = t;
  }
  return (t2 - t1) / (a + t2);
}
}  // namespace

TEST_CASE("TruncatedNormal: variance next to a far or narrow bound", "[noise]") {
  // JKB eq. 13.135 sums terms of order alpha^2 to a small variance: 2.6e-5 relative error on [5, 5.001],
  // 5e-8 on [30, inf) before the quadrature. References: scipy.integrate.quad of the moments in the offset
  // u = z - lower (density exp(-lower u - u^2/2), epsrel 1e-13), and the continued fraction above.
  CHECK_THAT(TruncatedNormal(0.0, 1.0, 5.0, 5.001).variance(), WithinRel(8.333322636822359e-08, 1e-12));
  CHECK_THAT(TruncatedNormal(0.0, 1.0, 30.0, 30.2).variance(), WithinRel(0.0010070068634032321, 1e-12));
  CHECK_THAT(TruncatedNormal(0.0, 1.0, -30.2, -30.0).variance(), WithinRel(0.0010070068634032321, 1e-12));
  for (const double a : {5.0, 20.0, 30.0, 37.0}) {
    CHECK_THAT(TruncatedNormal(0.0, 1.0, a, kInf).variance(), WithinRel(mills_variance(a), 1e-12));
    CHECK_THAT(TruncatedNormal(2.0, 3.0, 2.0 + 3.0 * a, kInf).variance(),
               WithinRel(9.0 * mills_variance(a), 1e-12));
  }
  CHECK_THAT(TruncatedNormal(0.0, 1.0, -kInf, -37.0).variance(), WithinRel(mills_variance(37.0), 1e-12));
  // a narrow interval about the mode: w^2/12 (1 - w^2/30 + O(w^4)) for [-w/2, w/2]
  const double w = 0.002;
  CHECK_THAT(TruncatedNormal(0.0, 1.0, -0.001, 0.001).variance(),
             WithinRel(w * w / 12.0 * (1.0 - w * w / 30.0), 1e-12));
  CHECK_THAT(TruncatedNormal(0.0, 1.0, -40.0, 40.0).variance(), WithinRel(1.0, 1e-15));
}

TEST_CASE("ShiftedNormal: Ke & Wu NLOS bias", "[noise]") {
  const ShiftedNormal d(513.0, 436.0);
  CHECK(d.shift() == 513.0);
  CHECK(d.stddev() == 436.0);
  CHECK(d.mean() == 513.0);
  CHECK(d.variance() == 436.0 * 436.0);
  CHECK_THAT(d.log_pdf(513.0), WithinRel(-std::log(436.0) - 0.9189385332046727, 1e-14));
  CHECK_THAT(d.cdf(513.0), WithinAbs(0.5, 1e-16));
  CHECK(d.from_standard_normal(2.0) == 513.0 + 872.0);
  check_common(d);
  check_sample_moments(d, 8);
}

TEST_CASE("AsymmetricNormal: values, moments, fit", "[noise]") {
  const AsymmetricNormal d(1.0, 1.0, 3.0);
  CHECK(d.mode() == 1.0);
  CHECK(d.sigma_left() == 1.0);
  CHECK(d.sigma_right() == 3.0);
  // pdf(mode) = 2/(sqrt(2 pi)(1 + 3)) = 0.19947114020071635
  CHECK_THAT(d.pdf(1.0), WithinRel(0.19947114020071635, 1e-14));
  // left: pdf(0) = 0.19947... exp(-1/2); right: pdf(4) = 0.19947... exp(-1/2) too (3 sigma_right = 3 away)
  CHECK_THAT(d.pdf(0.0), WithinRel(0.19947114020071635 * std::exp(-0.5), 1e-14));
  CHECK_THAT(d.pdf(4.0), WithinRel(0.19947114020071635 * std::exp(-0.5), 1e-14));
  CHECK_THAT(d.cdf(1.0), WithinRel(0.25, 1e-15));  // mass left of the mode sl/(sl + sr)
  CHECK_THAT(d.mean(), WithinRel(1.0 + 2.0 * std::sqrt(2.0 / nlosloc::kPi), 1e-15));
  CHECK_THAT(d.variance(), WithinRel(4.0 * (1.0 - 2.0 / nlosloc::kPi) + 3.0, 1e-15));
  check_distinct_tails(d);
  check_common(d);
  check_moments_by_integration(d);
  check_sample_moments(d, 9);

  SECTION("fit recovers the parameters of a large split-normal sample") {
    Rng rng(10);
    VecX s(20000);
    for (Eigen::Index i = 0; i < s.size(); ++i) s[i] = d.sample(rng);
    const AsymmetricNormal f = AsymmetricNormal::fit(s);
    CHECK_THAT(f.mode(), WithinAbs(1.0, 0.1));
    CHECK_THAT(f.sigma_left(), WithinAbs(1.0, 0.1));
    CHECK_THAT(f.sigma_right(), WithinAbs(3.0, 0.1));
    // It is a maximum of the likelihood: nudging any parameter lowers it.
    auto ll = [&](const AsymmetricNormal& a) {
      double acc = 0.0;
      for (Eigen::Index i = 0; i < s.size(); ++i) acc += a.log_pdf(s[i]);
      return acc;
    };
    const double l0 = ll(f);
    for (double e : {-1e-3, 1e-3}) {
      CHECK(ll(AsymmetricNormal(f.mode() + e, f.sigma_left(), f.sigma_right())) < l0);
      CHECK(ll(AsymmetricNormal(f.mode(), f.sigma_left() + e, f.sigma_right())) < l0);
      CHECK(ll(AsymmetricNormal(f.mode(), f.sigma_left(), f.sigma_right() + e)) < l0);
    }
  }
  SECTION("fit to Rayleigh errors (the CONG baseline of Huerta)") {
    const Rayleigh r = Rayleigh::from_variance(2000.0);
    Rng rng(11);
    VecX s(20000);
    for (Eigen::Index i = 0; i < s.size(); ++i) s[i] = r.sample(rng);
    const AsymmetricNormal f = AsymmetricNormal::fit(s);
    CHECK(f.sigma_left() < f.sigma_right());
    CHECK_THAT(f.mean(), WithinRel(r.mean(), 0.05));
  }
  SECTION("fit arguments") {
    CHECK_THROWS_WITH(AsymmetricNormal::fit(VecX::Ones(2)),
                      "AsymmetricNormal::fit: samples: expected at least 3 values, got 2");
    CHECK_THROWS_WITH(AsymmetricNormal::fit(VecX::Constant(5, 2.0)),
                      "AsymmetricNormal::fit: samples: expected a nonzero spread, got all values equal to 2");
    VecX bad = VecX::LinSpaced(5, 0.0, 1.0);
    bad[2] = kNaN;
    CHECK_THROWS_WITH(AsymmetricNormal::fit(bad),
                      "AsymmetricNormal::fit: samples: expected finite values (no NaN or inf)");
  }
}

TEST_CASE("Beta: Grisales quality statistics", "[noise]") {
  const Beta b23(2.0, 3.0);
  // pdf = 12 x (1 - x)^2: pdf(0.5) = 1.5; cdf(0.5) = I_0.5(2, 3) = 11/16
  CHECK_THAT(b23.pdf(0.5), WithinRel(1.5, 1e-14));
  CHECK_THAT(b23.cdf(0.5), WithinRel(0.6875, 1e-14));
  CHECK_THAT(b23.mean(), WithinRel(0.4, 1e-15));
  CHECK_THAT(b23.variance(), WithinRel(0.04, 1e-14));  // 6/(25 * 6)
  CHECK(b23.log_pdf(0.0) == -kInf);
  CHECK(b23.log_pdf(1.0) == -kInf);
  CHECK(b23.log_pdf(1.1) == -kInf);
  CHECK(b23.cdf(-0.5) == 0.0);
  CHECK(b23.cdf(1.5) == 1.0);
  CHECK_THAT(Beta(1.0, 3.0).pdf(0.0), WithinRel(3.0, 1e-14));  // exponent 0 at the edge
  CHECK(Beta(0.5, 3.0).pdf(0.0) == kInf);

  const Beta los(4.0, 1.5);
  CHECK(los.a() == 4.0);
  CHECK(los.b() == 1.5);
  // scipy.stats.beta(4, 1.5): cdf(0.5), pdf(0.5), median
  CHECK_THAT(los.cdf(0.5), WithinRel(0.11887865938082559, 1e-12));
  CHECK_THAT(los.pdf(0.5), WithinRel(0.8700727971631349, 1e-12));
  CHECK_THAT(los.quantile(0.5), WithinRel(0.7561355609542167, 1e-12));
  for (const Beta& d : {b23, los, Beta(3.0, 1.5), Beta(1.5, 4.0)}) {
    check_common(d);
    check_distinct_tails(d);
    check_sample_moments(d, 12);
  }
  check_moments_by_integration(b23);
  check_moments_by_integration(Beta(1.5, 4.0), 1e-5);
  // Far tails, where Boost's inversion threw or missed by a factor 2 (p below ~1e-100): the leading term
  // of DLMF 8.17.8, x = (p a B(a, b))^(1/a), checked through the cdf too.
  const double log_b = std::lgamma(4.0) + std::lgamma(1.5) - std::lgamma(5.5);
  for (const double p : {1e-100, 1e-120, 1e-300}) {
    const double x = los.quantile(p);
    CHECK_THAT(x, WithinRel(std::exp((std::log(p) + std::log(4.0) + log_b) / 4.0), 1e-13));
    CHECK_THAT(los.cdf(x), WithinRel(p, 1e-12));
  }
  CHECK_THAT(Beta(2.0, 5.0).quantile(1e-100), WithinRel(2.5819888974716112e-51, 1e-13));
  CHECK_THAT(los.cdf(los.from_standard_normal(-30.0)), WithinRel(4.906713927147908e-198, 1e-10));  // Phi(-30)
  CHECK(Beta(1.5, 4.0).from_standard_normal(30.0) == 1.0);  // 1 - y, y ~ 1e-50
  // Boost's root at p = 1e-300 was 3e-4 off for Beta(50, 20) (its cdf 2% off p) and its cdf of
  // Beta(300, 20) 0 at 1e-295: Newton's method on log I = log p with the series of DLMF 8.17.8 refines it.
  for (const auto& [a, b] : {std::pair{50.0, 20.0}, {20.0, 2.0}, {300.0, 20.0}}) {
    const Beta d(a, b);
    for (const double p : {1e-300, 1e-295, 1e-150}) {
      const double x = d.quantile(p);
      CHECK_THAT(d.cdf(x), WithinRel(p, 1e-12));
      CHECK(std::abs(d.cdf(x) - p) / (d.pdf(x) * x) < 1e-13);  // x's relative error, to first order
      CHECK_THAT(1.0 - Beta(b, a).quantile(1.0 - 1e-10), WithinRel(Beta(a, b).quantile(1e-10), 1e-5));
    }
  }
}

TEST_CASE("Empirical: Silverman Gaussian KDE as scipy", "[noise]") {
  VecX s4(4);
  s4 << 3.0, 0.0, 2.0, 1.0;
  const Empirical e4(s4);
  CHECK(e4.size() == 4);
  CHECK(e4.samples()[0] == 0.0);  // sorted
  // h = std(ddof=1) (3n/4)^(-1/5) = sqrt(5/3) 3^(-1/5)
  CHECK_THAT(e4.bandwidth(), WithinRel(std::sqrt(5.0 / 3.0) * std::pow(3.0, -0.2), 1e-15));
  CHECK_THAT(e4.bandwidth(), WithinRel(1.0363349000019686, 1e-14));
  // pdf(1.5) = mean of N(1.5; s_i, h^2) (scipy gaussian_kde gives 0.2388539)
  CHECK_THAT(e4.pdf(1.5), WithinRel(0.23885389941995944, 1e-13));
  // cdf(1) = mean of Phi((1 - s_i)/h)
  CHECK_THAT(e4.cdf(1.0), WithinRel(0.3817027433567734, 1e-13));
  CHECK_THAT(e4.mean(), WithinRel(1.5, 1e-15));
  CHECK_THAT(e4.variance(), WithinRel(1.25 + 1.0363349000019686 * 1.0363349000019686, 1e-14));
  // Symmetric samples: median at the centre.
  CHECK_THAT(e4.quantile(0.5), WithinAbs(1.5, 1e-12));
  // Far tail log density stays finite (log-sum-exp), and is -inf once (x - s_i)^2 overflows (it was NaN).
  CHECK(std::isfinite(e4.log_pdf(200.0)));
  CHECK(std::isfinite(e4.log_pdf(1e154)));
  CHECK(e4.log_pdf(1e300) == -kInf);
  CHECK(e4.log_pdf(-1e300) == -kInf);
  CHECK(e4.pdf(1e155) == 0.0);

  const Empirical e(kde_samples());
  check_common(e);
  check_distinct_tails(e);
  check_moments_by_integration(e);
  check_sample_moments(e, 13);
  // Deep tails through the transform: cdf(x) == Phi(u).
  CHECK_THAT(e.cdf(e.from_standard_normal(-8.0)), WithinRel(6.22096057427178e-16, 1e-9));
  CHECK_THAT(1.0 - e.cdf(e.from_standard_normal(5.0)), WithinRel(2.866515718791939e-07, 1e-6));
}

TEST_CASE("Distribution: type erasure", "[noise]") {
  const std::vector<Distribution> ds = {Normal(0.0, 1.0),
                                        Rayleigh(2.0),
                                        Exponential(0.5),
                                        Gev(0.4, 8.5, 4.25),
                                        TruncatedNormal(0.0, 1.0, 0.0, kInf),
                                        ShiftedNormal(513.0, 436.0),
                                        AsymmetricNormal(1.0, 1.0, 3.0),
                                        Beta(4.0, 1.5),
                                        Empirical(kde_samples())};
  CHECK(ds[0].holds<Normal>());
  CHECK(ds[1].holds<Rayleigh>());
  CHECK_FALSE(ds[1].holds<Normal>());
  CHECK(ds[8].holds<Empirical>());
  CHECK(std::string(ds[3].name()) == "Gev");
  CHECK(ds[2].get<Exponential>().mean() == 0.5);
  CHECK_THROWS_AS(ds[2].get<Normal>(), std::bad_variant_access);
  CHECK(std::holds_alternative<Beta>(ds[7].variant()));
  CHECK(Distribution().holds<Normal>());
  auto via_visit = [](const Distribution& d) {
    return std::visit([](const auto& x) { return x.mean(); }, d.variant());
  };
  Rng rng_a(42), rng_b(42);
  for (const Distribution& d : ds) {
    INFO(d.name());
    std::visit(
        [&](const auto& x) {
          CHECK(d.mean() == x.mean());
          CHECK(d.variance() == x.variance());
          CHECK(d.log_pdf(1.3) == x.log_pdf(1.3));
          CHECK(d.pdf(1.3) == x.pdf(1.3));
          CHECK(d.cdf(1.3) == x.cdf(1.3));
          CHECK(d.quantile(0.3) == x.quantile(0.3));
          CHECK(d.from_standard_normal(-0.7) == x.from_standard_normal(-0.7));
          CHECK(d.sample(rng_a) == x.sample(rng_b));
          CHECK(std::string(d.name()) == x.name());
        },
        d.variant());
    CHECK(via_visit(d) == d.mean());
    check_common(d);
  }
}

TEST_CASE("noise: bad parameters throw std::invalid_argument naming the argument", "[noise]") {
  CHECK_THROWS_WITH(Normal(0.0, 0.0), "Normal: std: expected a finite value > 0, got 0");
  CHECK_THROWS_WITH(Normal(kNaN, 1.0), "Normal: mean: expected a finite value, got nan");
  CHECK_THROWS_WITH(Normal(0.0, kInf), "Normal: std: expected a finite value > 0, got inf");
  CHECK_THROWS_WITH(Rayleigh(-1.0), "Rayleigh: scale: expected a finite value > 0, got -1");
  CHECK_THROWS_WITH(Rayleigh::from_variance(-2.5),
                    "Rayleigh: variance: expected a finite value > 0, got -2.5");
  CHECK_THROWS_WITH(Exponential(0.0), "Exponential: mean: expected a finite value > 0, got 0");
  CHECK_THROWS_WITH(Gev(kInf, 0.0, 1.0), "Gev: shape: expected a finite value, got inf");
  CHECK_THROWS_WITH(Gev(0.1, kNaN, 1.0), "Gev: loc: expected a finite value, got nan");
  CHECK_THROWS_WITH(Gev(0.1, 0.0, -4.25), "Gev: scale: expected a finite value > 0, got -4.25");
  CHECK_THROWS_WITH(TruncatedNormal(kInf, 1.0, 0.0, 1.0),
                    "TruncatedNormal: mu: expected a finite value, got inf");
  CHECK_THROWS_WITH(TruncatedNormal(0.0, 0.0, 0.0, 1.0),
                    "TruncatedNormal: sigma: expected a finite value > 0, got 0");
  CHECK_THROWS_WITH(TruncatedNormal(0.0, 1.0, 1.0, 0.0),
                    "TruncatedNormal: lower, upper: expected lower < upper, got lower=1, upper=0");
  CHECK_THROWS_WITH(TruncatedNormal(0.0, 1.0, kNaN, 1.0),
                    "TruncatedNormal: lower: expected a value < +inf, got nan");
  CHECK_THROWS_WITH(TruncatedNormal(0.0, 1.0, 0.0, -kInf),
                    "TruncatedNormal: upper: expected a value > -inf, got -inf");
  CHECK_THROWS_WITH(TruncatedNormal(0.0, 1.0, 50.0, 51.0),
                    Catch::Contains("no representable probability mass"));
  CHECK_THROWS_WITH(ShiftedNormal(0.0, 1.0), "ShiftedNormal: shift: expected a finite value > 0, got 0");
  CHECK_THROWS_WITH(ShiftedNormal(-513.0, 1.0),
                    "ShiftedNormal: shift: expected a finite value > 0, got -513");
  CHECK_THROWS_WITH(ShiftedNormal(513.0, -1.0), "ShiftedNormal: std: expected a finite value > 0, got -1");
  CHECK_THROWS_WITH(AsymmetricNormal(kNaN, 1.0, 1.0),
                    "AsymmetricNormal: mode: expected a finite value, got nan");
  CHECK_THROWS_WITH(AsymmetricNormal(0.0, 0.0, 1.0),
                    "AsymmetricNormal: sigma_left: expected a finite value > 0, got 0");
  CHECK_THROWS_WITH(AsymmetricNormal(0.0, 1.0, -1.0),
                    "AsymmetricNormal: sigma_right: expected a finite value > 0, got -1");
  CHECK_THROWS_WITH(Beta(0.0, 1.0), "Beta: a: expected a finite value > 0, got 0");
  CHECK_THROWS_WITH(Beta(1.0, kNaN), "Beta: b: expected a finite value > 0, got nan");
  CHECK_THROWS_WITH(Empirical(VecX::Ones(1)), "Empirical: samples: expected at least 2 values, got 1");
  CHECK_THROWS_WITH(Empirical(VecX::Constant(3, 0.5)),
                    "Empirical: samples: expected a nonzero spread (std > 0), got all values equal to 0.5");
  VecX inf_samples = VecX::LinSpaced(4, 0.0, 1.0);
  inf_samples[1] = kInf;
  CHECK_THROWS_WITH(Empirical(inf_samples), "Empirical: samples: expected finite values (no NaN or inf)");
  CHECK_THROWS_WITH(Rayleigh(1.0).quantile(1.0),
                    "Rayleigh::quantile: p: expected a probability in (0, 1), got 1");
  CHECK_THROWS_WITH(Distribution(Beta(2.0, 2.0)).quantile(-0.5),
                    "Beta::quantile: p: expected a probability in (0, 1), got -0.5");
  // finite samples whose spread overflows: refused, not a density with bandwidth inf
  CHECK_THROWS_WITH(Empirical((VecX(3) << 0.0, 1e200, -1e200).finished()),
                    "Empirical: samples: spread too large (its variance overflows)");
}
