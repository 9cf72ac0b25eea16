#pragma once
/// \file metrics.hpp
/// Statistics of Monte Carlo position errors: percentiles (Ke & Wu Table 1 reports the 67% and 95% errors,
/// the FCC criteria), empirical CDF (Huerta Figs. 14-15), RMSE over time (Ke & Wu Sec. 6.1 RMSE_k), the
/// probability that the error is at most a threshold (Ke & Wu Sec. 6.4) and mean time per step.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "nlosloc/core/types.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc {
namespace detail {
inline constexpr double kMetricNaN = std::numeric_limits<double>::quiet_NaN();
inline void check_percent(double q) {
  NLOSLOC_ENSURE(q >= 0.0 && q <= 100.0, "q: expected a percentage in [0, 100], got " + std::to_string(q));
}
/// numpy's _lerp: a + (b - a) t, computed from b when t >= 0.5 (so t = 1 gives b exactly). At a rank
/// itself (t = 0, or a = b) the value is returned as it is, so an inf beside it does not turn it into
/// inf * 0 = NaN (numpy's formula would). Between an infinite rank and another (0 < t < 1) the result is
/// the infinite one: -inf from a = -inf (a + diff t was -inf + inf = NaN), +inf towards b = +inf.
inline double lerp(double a, double b, double t) {
  if (t == 0.0 || a == b) return a;
  const double diff = b - a;
  if (std::isinf(a)) return a;
  if (std::isinf(diff))
    return a + diff * t;  // t > 0 towards an infinite rank: infinite (b - diff would be NaN)
  return t >= 0.5 ? b - diff * (1.0 - t) : a + diff * t;
}
}  // namespace detail

namespace sim {

/// q-th percentile (q in [0, 100]) of ascending `sorted` values by linear interpolation between closest
/// ranks, index h = (n - 1) q/100 (Hyndman & Fan 1996 definition 7, numpy.percentile's default "linear",
/// computed the way numpy does). NaN when the input is empty or holds a NaN (which sorts last).
inline double percentile_sorted(const std::vector<double>& sorted, double q) {
  detail::check_percent(q);
  const std::size_t n = sorted.size();
  if (n == 0 || std::isnan(sorted.back())) return detail::kMetricNaN;
  const double h = (static_cast<double>(n) - 1.0) * (q / 100.0);
  if (h >= static_cast<double>(n - 1)) return sorted[n - 1];
  const double lo = std::floor(h);
  const auto i = static_cast<std::size_t>(lo);
  return detail::lerp(sorted[i], sorted[i + 1], h - lo);
}

/// Sorts values ascending with NaN last.
inline void sort_values(std::vector<double>& v) {
  std::sort(v.begin(), v.end(), [](double a, double b) { return std::isnan(b) ? !std::isnan(a) : a < b; });
}

/// Percentiles qs (each in [0, 100]) of `values`, sorting once (see percentile_sorted).
inline std::vector<double> percentiles(std::vector<double> values, const std::vector<double>& qs) {
  sort_values(values);
  std::vector<double> r;
  r.reserve(qs.size());
  for (double q : qs) r.push_back(percentile_sorted(values, q));
  return r;
}

/// q-th percentile (q in [0, 100]) of `values`, numpy.percentile's default definition.
inline double percentile(std::vector<double> values, double q) {
  return percentiles(std::move(values), {q})[0];
}

/// Empirical CDF: x ascending, p[i] = (number of values <= x[i]) / n = P(error <= x[i]); tied values share
/// the rank of the last of them (a NaN, sorted last, keeps its own rank i + 1).
struct Ecdf {
  std::vector<double> x;
  std::vector<double> p;
};

/// ECDF of `values` (NaN sort last and count in n). max_points > 1 keeps at most that many points evenly
/// spaced in rank, always including the smallest and largest; 0 keeps all.
inline Ecdf ecdf(std::vector<double> values, std::size_t max_points = 0) {
  NLOSLOC_ENSURE(max_points != 1, "max_points: expected 0 (all) or >= 2, got 1");
  sort_values(values);
  const std::size_t n = values.size();
  Ecdf e;
  const std::size_t m = (max_points == 0 || n <= max_points) ? n : max_points;
  const auto finite_end =
      std::partition_point(values.begin(), values.end(), [](double v) { return !std::isnan(v); });
  e.x.reserve(m);
  e.p.reserve(m);
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t i =
        m == n ? j
               : static_cast<std::size_t>(std::llround(static_cast<double>(j) * static_cast<double>(n - 1) /
                                                       static_cast<double>(m - 1)));
    e.x.push_back(values[i]);
    // the end of x[i]'s run of ties (i + 1 was the rank of each, so P(error <= x) was too small)
    const std::size_t le =
        std::isnan(values[i])
            ? i + 1
            : static_cast<std::size_t>(
                  std::upper_bound(values.begin() + static_cast<std::ptrdiff_t>(i), finite_end, values[i]) -
                  values.begin());
    e.p.push_back(static_cast<double>(le) / static_cast<double>(n));
  }
  return e;
}

/// RMSE over time across runs of a runs x T matrix of position error norms e_{k,i} = ||p_hat - p||:
/// RMSE_k = sqrt(1/N sum_i e_{k,i}^2) (Ke & Wu Sec. 6.1).
inline VecX rmse_over_time(const RowMatX& errors) {
  NLOSLOC_ENSURE(errors.rows() > 0, "errors: expected at least one run (row)");
  return (errors.array().square().colwise().sum() / static_cast<double>(errors.rows())).sqrt().transpose();
}

/// Fraction of values <= threshold (Ke & Wu Sec. 6.4: probability that the error is at most 5 m). NaN counts
/// as above the threshold; NaN for an empty input.
inline double probability_within(const std::vector<double>& values, double threshold) {
  NLOSLOC_ENSURE(!std::isnan(threshold), "threshold: expected a number, got NaN");
  if (values.empty()) return detail::kMetricNaN;
  const auto c =
      std::count_if(values.begin(), values.end(), [threshold](double v) { return v <= threshold; });
  return static_cast<double>(c) / static_cast<double>(values.size());
}

/// Arithmetic mean (e.g. of per-run times per step); NaN for an empty input.
template <class D>
double mean_of(const Eigen::DenseBase<D>& v) {
  return v.size() == 0 ? detail::kMetricNaN : v.derived().mean();
}
inline double mean_of(const std::vector<double>& v) {
  return mean_of(Eigen::Map<const VecX>(v.data(), static_cast<Eigen::Index>(v.size())));
}

/// The errors of every run at steps k >= discard, run after run (the samples the paper's percentiles use).
inline std::vector<double> pooled_errors(const RowMatX& errors, int discard) {
  NLOSLOC_ENSURE(discard >= 0 && discard < errors.cols(), "discard: expected 0 <= discard < steps (" +
                                                              std::to_string(errors.cols()) + "), got " +
                                                              std::to_string(discard));
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(errors.rows() * (errors.cols() - discard)));
  for (Eigen::Index r = 0; r < errors.rows(); ++r)
    for (Eigen::Index k = discard; k < errors.cols(); ++k) v.push_back(errors(r, k));
  return v;
}

}  // namespace sim
}  // namespace nlosloc
