#pragma once
/// \file gaussian.hpp
/// Gaussian belief N(mean, cov) over a fixed-size (or Dynamic) state.
#include <string>

#include "nlosloc/core/cholesky.hpp"
#include "nlosloc/core/types.hpp"

namespace nlosloc {

/// Gaussian belief: mean (N) and covariance (N x N), the output of every filter step.
template <int N>
struct Gaussian {
  Vec<N> mean;
  Mat<N, N> cov;

  Gaussian() {
    if constexpr (N != Eigen::Dynamic) {
      mean.setZero();
      cov.setIdentity();
    }
  }
  Gaussian(const Vec<N>& m, const Mat<N, N>& P) : mean(m), cov(P) {}

  int dim() const { return static_cast<int>(mean.size()); }

  /// Throws std::invalid_argument naming `name` unless mean is finite and cov is symmetric PD.
  void validate(const char* name = "belief") const {
    validate((std::string(name) + ".mean").c_str(), (std::string(name) + ".cov").c_str());
  }
  /// validate() with the errors naming the mean and the covariance as given (the arguments of a binding).
  void validate(const char* mean_name, const char* cov_name) const {
    detail::ensure_shape(cov, mean.size(), mean.size(), cov_name);
    detail::ensure_finite(mean, mean_name);
    if (!is_spd(cov))
      detail::throw_invalid_argument(std::string(cov_name) +
                                     ": expected a symmetric positive definite matrix");
  }
};

}  // namespace nlosloc
