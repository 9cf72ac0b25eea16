#pragma once
/// \file logsumexp.hpp
/// Log-space arithmetic for particle weights (weights are kept as logs, normalised by log-sum-exp).
#include <cmath>
#include <limits>

#include "nlosloc/core/types.hpp"

namespace nlosloc {

/// log(sum_i exp(v_i)), exact for -inf entries; returns -inf for an empty or all -inf input.
template <class D>
double log_sum_exp(const Eigen::DenseBase<D>& v) {
  if (v.size() == 0) return -std::numeric_limits<double>::infinity();
  const double m = v.maxCoeff();
  if (!std::isfinite(m)) return m;  // all -inf (or a +inf / NaN, which propagate)
  return m + std::log((v.derived().array() - m).exp().sum());
}

/// True when every entry is a valid log weight: finite, or -inf (a particle ruled out); never NaN or +inf.
template <class D>
bool are_log_weights(const Eigen::DenseBase<D>& v) {
  const auto a = v.derived().array();
  return !a.isNaN().any() && !(a == std::numeric_limits<double>::infinity()).any();
}

/// Subtracts log_sum_exp(v) from v in place so that sum(exp(v)) = 1; returns the normaliser.
template <class D>
double log_normalize(Eigen::DenseBase<D>& v) {
  const double z = log_sum_exp(v);
  if (std::isfinite(z)) v.derived().array() -= z;
  return z;
}

/// log N(x; 0, S) from the Cholesky factor L of S and x (size m): -0.5 (m log 2pi + log|S| + x^T S^-1 x).
template <class DL, class DX>
double gaussian_log_pdf_chol(const Eigen::MatrixBase<DL>& L, const Eigen::MatrixBase<DX>& x) {
  const double log_det = 2.0 * L.diagonal().array().log().sum();
  const typename DX::PlainObject z = L.template triangularView<Eigen::Lower>().solve(x);
  return -0.5 * (static_cast<double>(x.size()) * std::log(2.0 * kPi) + log_det + z.squaredNorm());
}

}  // namespace nlosloc
