#pragma once
/// \file common.hpp
/// Pieces shared by the Gaussian filters: the step result, input checks, and the Kalman update tail
/// (gain, posterior, predictive log-likelihood) with missing-row handling and no per-step allocation.
#include <cmath>
#include <limits>
#include <string>

#include "nlosloc/core/cholesky.hpp"
#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/core/types.hpp"

namespace nlosloc {

/// What one filter update reports.
struct StepResult {
  /// log p(y_t | y_1:t-1, s) under the filter's Gaussian predictive N(y; z_hat, S) over the rows used
  /// (Huerta (III.2) weights particles with it). 0 when no row was used.
  double log_likelihood = 0.0;
  int rows_used = 0;                            ///< rows that were not NaN
  CholeskyStatus status = CholeskyStatus::kOk;  ///< worst factorisation outcome of the step
  double jitter = 0.0;                          ///< diagonal added by the Cholesky fallback, if any
};

namespace detail {

/// A <- (A + A^T)/2 in place, without a temporary.
template <class M>
void symmetrize(M& A) {
  for (Eigen::Index j = 0; j < A.cols(); ++j)
    for (Eigen::Index i = j + 1; i < A.rows(); ++i) A(i, j) = A(j, i) = 0.5 * (A(i, j) + A(j, i));
}

/// In-place Cholesky-Banachiewicz on the lower triangle of a small dense matrix (the upper triangle is
/// ignored and left as is). Returns false when a pivot is not positive (A not positive definite), and
/// then, when asked, the row and the pivot (for a message). Hand-written because Eigen's dynamic-size LLT
/// goes through blocked level-3 kernels whose set-up costs more than the arithmetic at the sizes of a
/// measurement update (m <= ~20).
template <class M>
bool small_cholesky_inplace(M& A, Eigen::Index* bad_row = nullptr, double* bad_pivot = nullptr) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    double d = A(j, j);
    for (Eigen::Index k = 0; k < j; ++k) d -= A(j, k) * A(j, k);
    if (!(d > 0.0)) {
      if (bad_row) *bad_row = j;
      if (bad_pivot) *bad_pivot = d;
      return false;
    }
    d = std::sqrt(d);
    A(j, j) = d;
    for (Eigen::Index i = j + 1; i < n; ++i) {
      double v = A(i, j);
      for (Eigen::Index k = 0; k < j; ++k) v -= A(i, k) * A(j, k);
      A(i, j) = v / d;
    }
  }
  return true;
}

/// Solves L w = b in place for every column of B (L lower triangular, from small_cholesky_inplace).
template <class ML, class MB>
void small_forward_inplace(const ML& L, MB& B) {
  const Eigen::Index n = L.rows();
  for (Eigen::Index c = 0; c < B.cols(); ++c)
    for (Eigen::Index i = 0; i < n; ++i) {
      double v = B(i, c);
      for (Eigen::Index k = 0; k < i; ++k) v -= L(i, k) * B(k, c);
      B(i, c) = v / L(i, i);
    }
}

/// Lower Cholesky factor of the state covariance P with the documented fallback (core/cholesky.hpp):
/// plain, then jitter eps * mean|diag| for eps = 1e-12, 1e-10, 1e-8. L receives the factor.
template <int N>
CholeskyStatus factor_state_cov(const Mat<N, N>& P, Mat<N, N>& L, double* jitter) {
  *jitter = 0.0;
  if (!P.allFinite()) return CholeskyStatus::kFailed;
  L = P;
  if (small_cholesky_inplace(L)) {
    L.template triangularView<Eigen::StrictlyUpper>().setZero();
    return CholeskyStatus::kOk;
  }
  const double scale = std::max(P.diagonal().cwiseAbs().mean(), 1e-300);
  for (double eps : {1e-12, 1e-10, 1e-8}) {
    L = P;
    L.diagonal().array() += eps * scale;
    if (small_cholesky_inplace(L)) {
      L.template triangularView<Eigen::StrictlyUpper>().setZero();
      *jitter = eps * scale;
      return CholeskyStatus::kJittered;
    }
  }
  return CholeskyStatus::kFailed;
}

/// Throws unless the measurement model's state layout has the motion model's state size N.
template <int N, class Meas>
void check_layout(const Meas& meas) {
  if (meas.layout().dim != N)
    throw_invalid_argument("measurements: layout dimension " + std::to_string(meas.layout().dim) +
                           " does not match the motion model's state size " + std::to_string(N));
}

inline CholeskyStatus worse(CholeskyStatus a, CholeskyStatus b) {
  return static_cast<int>(a) > static_cast<int>(b) ? a : b;
}

/// Kalman update tail shared by KF, EKF and UKF. Given the predicted measurement z_hat, its covariance S
/// (including the noise), the cross covariance Pxz and the measurement y, it computes the gain and the
/// posterior. Rows with NaN in y are neutralised (zero innovation, unit S row/column, zero Pxz column)
/// so the sizes stay fixed and nothing is allocated. Buffers are sized once by resize().
template <int N>
class UpdateTail {
 public:
  using MatNm = Eigen::Matrix<double, N, Eigen::Dynamic>;

  void resize(int m) {
    S.setZero(m, m);
    Pxz.setZero(N, m);
    zhat.setZero(m);
    nu.setZero(m);
    B_.setZero(m, N + 1);
    L_.setZero(m, m);
    dinv_.setZero(m);
  }

  /// Applies the update to (x, P) (outputs may alias nothing else). `wrap` turns a raw residual into a
  /// wrapped one (angles). Returns false (and leaves x, P untouched) when S cannot be factorised or the
  /// gain is not finite.
  template <class Wrap>
  bool apply(const VecX& y, Wrap&& wrap, Vec<N>& x, Mat<N, N>& P, StepResult& res) {
    const Eigen::Index m = y.size();
    int used = 0;
    nu = y - zhat;
    wrap(nu);
    for (Eigen::Index i = 0; i < m; ++i) {
      if (std::isnan(y[i])) {  // missing row: skipped for this step
        nu[i] = 0.0;
        S.row(i).setZero();
        S.col(i).setZero();
        S(i, i) = 1.0;
        Pxz.col(i).setZero();
      } else {
        ++used;
      }
    }
    res.rows_used = used;
    if (used == 0) {
      res.log_likelihood = 0.0;
      return true;
    }
    // Cholesky of S with the documented fallback (core/cholesky.hpp): plain, then jitter eps * mean|diag|.
    // Non-finite entries make a pivot fail or come out non-finite; both are caught below.
    symmetrize(S);
    CholeskyStatus st = CholeskyStatus::kOk;
    double jit = 0.0;
    if (!factor_s()) {
      const double scale = std::max(S.diagonal().cwiseAbs().mean(), 1e-300);
      st = CholeskyStatus::kFailed;
      for (double eps : {1e-12, 1e-10, 1e-8}) {
        if (factor_s(eps * scale)) {
          st = CholeskyStatus::kJittered;
          jit = eps * scale;
          break;
        }
      }
    }
    res.status = worse(res.status, st);
    res.jitter = std::max(res.jitter, jit);
    if (st == CholeskyStatus::kFailed) return fail(res);
    // log|S| = 2 sum log L_ii, taken as the log of a running product of the pivots (one log call instead
    // of m; the product is folded into the sum before it can overflow or underflow).
    double log_det = 0.0, prod = 1.0;
    for (Eigen::Index i = 0; i < m; ++i) {
      prod *= L_(i, i);
      if (prod > 1e150 || prod < 1e-150) {
        log_det += std::log(prod);
        prod = 1.0;
      }
    }
    log_det += std::log(prod);
    if (!std::isfinite(log_det)) return fail(res);  // an infinite pivot: S had an infinite entry
    // One forward substitution for B = L^-1 [Pxz^T | nu] = [W | w], row by row on fixed-width rows.
    // Then x += K nu = W^T w and P -= K S K^T = Pxz S^-1 Pxz^T = W^T W.
    for (Eigen::Index i = 0; i < m; ++i) {
      auto bi = B_.row(i);
      bi.template head<N>() = Pxz.col(i).transpose();
      bi[N] = nu[i];
      for (Eigen::Index k = 0; k < i; ++k) bi -= L_(i, k) * B_.row(k);
      bi *= dinv_[i];
    }
    if (!B_.allFinite()) return fail(res);
    double quad = 0.0;
    Vec<N> dx = Vec<N>::Zero();
    Mat<N, N> dP = Mat<N, N>::Zero();
    for (Eigen::Index i = 0; i < m; ++i) {
      const Eigen::Matrix<double, 1, N> wi = B_.row(i).template head<N>();
      const double wn = B_(i, N);
      quad += wn * wn;
      dx.noalias() += wn * wi.transpose();
      dP.noalias() += wi.transpose() * wi;  // outer products are exactly symmetric: P stays symmetric
    }
    x += dx;
    P -= dP;
    // log N(nu; 0, S) over the used rows; padded rows have unit pivots and zero innovation.
    constexpr double kLog2Pi = 1.8378770664093454835606594728112;  // log(2 pi)
    res.log_likelihood = -0.5 * (static_cast<double>(used) * kLog2Pi + 2.0 * log_det + quad);
    return true;
  }

  MatX S;
  MatNm Pxz;
  VecX zhat, nu;

 private:
  static bool fail(StepResult& res) {
    res.status = CholeskyStatus::kFailed;
    return false;
  }
  /// Lower Cholesky factor of S + jitter I into L_ (Cholesky-Banachiewicz, lower triangle of S only) and
  /// the reciprocal pivots into dinv_. False when a pivot is not positive.
  bool factor_s(double jitter = 0.0) {
    const Eigen::Index n = S.rows();
    for (Eigen::Index j = 0; j < n; ++j) {
      double d = S(j, j) + jitter;
      for (Eigen::Index k = 0; k < j; ++k) d -= L_(j, k) * L_(j, k);
      if (!(d > 0.0)) return false;
      d = std::sqrt(d);
      L_(j, j) = d;
      dinv_[j] = 1.0 / d;
      for (Eigen::Index i = j + 1; i < n; ++i) {
        double v = S(i, j);
        for (Eigen::Index k = 0; k < j; ++k) v -= L_(i, k) * L_(j, k);
        L_(i, j) = v * dinv_[j];
      }
    }
    return true;
  }

  Eigen::Matrix<double, Eigen::Dynamic, N + 1, Eigen::RowMajor> B_;
  MatX L_;
  VecX dinv_;
};

}  // namespace detail
}  // namespace nlosloc
