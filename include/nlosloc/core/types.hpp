#pragma once
/// \file types.hpp
/// Eigen aliases used across nlosloc. Fixed sizes for the state, Dynamic for counts known at run time.
#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "nlosloc/core/ensure.hpp"

namespace nlosloc {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int R, int C>
using Mat = Eigen::Matrix<double, R, C>;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
using VecXi = Eigen::VectorXi;

/// Sizes of sigma-point sets: 2n+1 points, Dynamic stays Dynamic.
constexpr int sigma_count(int n) { return n == Eigen::Dynamic ? Eigen::Dynamic : 2 * n + 1; }

/// Speed of light in vacuum, m/s (used by the two-way-ranging model, Grisales eq. 17).
constexpr double kSpeedOfLight = 299792458.0;
constexpr double kPi = 3.14159265358979323846;

/// Wraps an angle to (-pi, pi].
inline double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * kPi);  // in [-pi, pi]
  return a <= -kPi ? a + 2.0 * kPi : a;
}

namespace detail {
template <class D>
bool all_finite(const Eigen::DenseBase<D>& m) {
  return m.allFinite();
}
inline std::string shape_str(Eigen::Index r, Eigen::Index c) {
  return "(" + std::to_string(r) + ", " + std::to_string(c) + ")";
}
/// Throws unless m is rows x cols (a negative expected size is not checked).
template <class D>
void ensure_shape(const Eigen::DenseBase<D>& m, Eigen::Index rows, Eigen::Index cols, const char* name) {
  if ((rows >= 0 && m.rows() != rows) || (cols >= 0 && m.cols() != cols)) {
    throw_invalid_argument(std::string(name) + ": expected shape " + shape_str(rows, cols) + ", got " +
                           shape_str(m.rows(), m.cols()));
  }
}
template <class D>
void ensure_finite(const Eigen::DenseBase<D>& m, const char* name) {
  if (!m.allFinite()) throw_invalid_argument(std::string(name) + ": expected finite values (no NaN or inf)");
}
/// Throws unless v has n entries, none infinite (NaN marks a missing entry, and is allowed): "<name>:
/// expected <expected>; got inf at <item> i". Shared by the measurement and quality-statistic checks.
template <class D>
void ensure_finite_or_missing(const Eigen::MatrixBase<D>& v, Eigen::Index n, const char* name,
                              const char* expected, const char* item) {
  ensure_shape(v, n, 1, name);
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (std::isinf(v[i]))
      throw_invalid_argument(std::string(name) + ": expected " + expected + "; got inf at " + item + " " +
                             std::to_string(i));
}
/// Throws unless the measurement vector `name` has m entries, each finite or NaN (missing).
template <class D>
void check_measurement(const Eigen::MatrixBase<D>& y, Eigen::Index m, const char* name = "y") {
  ensure_finite_or_missing(y, m, name, "finite values, or NaN for a missing row", "row");
}
inline void ensure_positive(double v, const char* name) {
  if (!(v > 0.0) || !std::isfinite(v))
    throw_invalid_argument(std::string(name) + ": expected a finite value > 0, got " + std::to_string(v));
}
inline void ensure_nonnegative(double v, const char* name) {
  if (!(v >= 0.0) || !std::isfinite(v))
    throw_invalid_argument(std::string(name) + ": expected a finite value >= 0, got " + std::to_string(v));
}
}  // namespace detail
}  // namespace nlosloc
