#pragma once
/// \file cholesky.hpp
/// Cholesky factorisation with a documented, reported fallback.
///
/// Policy: first a plain LLT of the symmetric part. If that fails (not positive definite to working
/// precision), the factorisation is retried with a diagonal jitter eps * max(mean(diag), tiny) * I for
/// eps = 1e-12, 1e-10, 1e-8. The outcome says which path was taken, so the caller can report it; if all
/// attempts fail the result is kFailed and the factor is unusable. Nothing is patched silently: filters
/// expose the status of every step and throw NumericalError on kFailed.
#include <Eigen/Cholesky>

#include "nlosloc/core/types.hpp"

namespace nlosloc {

/// Outcome of robust_cholesky.
enum class CholeskyStatus { kOk = 0, kJittered = 1, kFailed = 2 };

inline const char* to_string(CholeskyStatus s) {
  switch (s) {
    case CholeskyStatus::kOk: return "ok";
    case CholeskyStatus::kJittered: return "jittered";
    default: return "failed";
  }
}

/// Lower Cholesky factor L of A (A = L L^T), with the fallback documented above.
/// `A` must be square; `L` is overwritten (same size as A). `jitter_used` receives the added diagonal.
/// A 0 x 0 matrix is positive definite (vacuously): kOk with an empty L.
template <class DA, class DL>
CholeskyStatus robust_cholesky(const Eigen::MatrixBase<DA>& A, Eigen::MatrixBase<DL>& L,
                               double* jitter_used = nullptr) {
  using M = typename DL::PlainObject;
  const Eigen::Index n = A.rows();
  if (jitter_used) *jitter_used = 0.0;
  if (n == 0) {  // Eigen's minCoeff below is undefined on an empty matrix
    L.derived().resize(0, 0);
    return CholeskyStatus::kOk;
  }
  if (!A.allFinite()) return CholeskyStatus::kFailed;
  M S = 0.5 * (A + A.transpose());
  Eigen::LLT<M> llt(S);
  if (llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() > 0.0) {
    L.derived() = llt.matrixL();
    return CholeskyStatus::kOk;
  }
  const double scale = std::max(S.diagonal().cwiseAbs().sum() / static_cast<double>(n), 1e-300);
  for (double eps : {1e-12, 1e-10, 1e-8}) {
    M Sj = S;
    Sj.diagonal().array() += eps * scale;
    llt.compute(Sj);
    if (llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() > 0.0) {
      L.derived() = llt.matrixL();
      if (jitter_used) *jitter_used = eps * scale;
      return CholeskyStatus::kJittered;
    }
  }
  return CholeskyStatus::kFailed;
}

namespace detail {
/// max|A| (at least 1e-300) when A is square, finite and symmetric within rel_tol of it; 0 otherwise.
/// rel_tol must be finite >= 0 (a NaN one passed any matrix, a negative one none).
template <class D>
double symmetric_scale(const Eigen::MatrixBase<D>& A, double rel_tol) {
  NLOSLOC_ENSURE(std::isfinite(rel_tol) && rel_tol >= 0.0,
                 "rel_tol: expected a finite value >= 0, got " + detail::fmt_shortest(rel_tol));
  if (A.rows() != A.cols() || !A.allFinite()) return 0.0;
  if (A.size() == 0) return 1e-300;  // maxCoeff is undefined on an empty matrix, which is symmetric
  const double s = std::max(A.cwiseAbs().maxCoeff(), 1e-300);
  return (A - A.transpose()).cwiseAbs().maxCoeff() > rel_tol * s ? 0.0 : s;
}
}  // namespace detail

/// True when A is symmetric (to rel. tolerance) and positive definite; true for 0 x 0 (vacuously), as
/// robust_cholesky's kOk. rel_tol: finite >= 0, else std::invalid_argument.
template <class D>
bool is_spd(const Eigen::MatrixBase<D>& A, double rel_tol = 1e-9) {
  if (detail::symmetric_scale(A, rel_tol) == 0.0) return false;
  if (A.size() == 0) return true;
  Eigen::LLT<typename D::PlainObject> llt(0.5 * (A + A.transpose()));
  return llt.info() == Eigen::Success;
}

/// True when A is symmetric (to rel. tolerance) and positive semi-definite: the pivots of its LDLT are
/// >= -rel_tol max|A| (a weighted particle set's covariance, singular along a direction without spread).
/// 0 x 0 and rel_tol as for is_spd.
template <class D>
bool is_spsd(const Eigen::MatrixBase<D>& A, double rel_tol = 1e-9) {
  const double s = detail::symmetric_scale(A, rel_tol);
  if (s == 0.0) return false;
  if (A.size() == 0) return true;
  Eigen::LDLT<typename D::PlainObject> ldlt(0.5 * (A + A.transpose()));
  return ldlt.info() == Eigen::Success && (ldlt.vectorD().array() >= -rel_tol * s).all();
}

}  // namespace nlosloc
