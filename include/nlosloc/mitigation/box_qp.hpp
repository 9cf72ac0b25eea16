#pragma once
/// \file box_qp.hpp
/// A small adapter for box-constrained convex quadratic programs
///     minimise 1/2 x^T H x + g^T x   subject to   lower <= x <= upper,
/// the form of Ke & Wu eq. (14) with the bounds of eq. (15). The interface names no solver type, so the
/// solver can be swapped: box_qp_proxsuite.hpp implements it on proxsuite's dense QP (DESIGN.md), and tests
/// inject their own implementations (e.g. one that always fails, to exercise the callers' fallbacks).
#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "nlosloc/core/types.hpp"

namespace nlosloc::mitigation {

/// Outcome of one BoxQp::solve.
enum class QpStatus {
  kSolved = 0,            ///< converged to the requested accuracy
  kMaxIterations = 1,     ///< iteration limit reached (x is the last iterate, not trusted)
  kPrimalInfeasible = 2,  ///< the solver reports no feasible point
  kDualInfeasible = 3,    ///< the objective is unbounded below on the box (cannot happen for H PSD)
  kFailed = 4             ///< anything else: non-finite output, a solver exception, not run
};

/// Name of a QpStatus ("solved", "max_iterations", ...).
inline const char* to_string(QpStatus s) {
  switch (s) {
    case QpStatus::kSolved: return "solved";
    case QpStatus::kMaxIterations: return "max_iterations";
    case QpStatus::kPrimalInfeasible: return "primal_infeasible";
    case QpStatus::kDualInfeasible: return "dual_infeasible";
    case QpStatus::kFailed: return "failed";
  }
  return "failed";
}

/// Accuracy settings shared by the implementations (defaults: DESIGN.md proxsuite notes).
struct BoxQpSettings {
  double eps_abs = 1e-9;              ///< absolute primal/dual residual tolerance, > 0
  bool check_duality_gap = true;      ///< also require a small duality gap (DESIGN.md: without it
                                      ///< proxsuite stops ~1e-5 away on rank-deficient box LS)
  double eps_duality_gap_abs = 1e-9;  ///< absolute duality-gap tolerance, > 0
  int max_iter = 1000;                ///< outer iteration limit, >= 1
  /// Ruiz equilibration before each solve. Off by default: it costs ~40% of a 3-variable solve, and the
  /// callers here pass unit-scaled problems (BiasEstimator scales b by sqrt(mean R)).
  bool compute_preconditioner = false;
};

/// What one solve reports; the minimiser is read from BoxQp::x().
struct QpResult {
  QpStatus status = QpStatus::kFailed;
  int iterations = 0;      ///< solver iterations (0 when not run)
  double objective = 0.0;  ///< 1/2 x^T H x + g^T x at the returned x (NaN when not solved)
  bool ok() const { return status == QpStatus::kSolved; }
};

/// Box-constrained convex QP solver of fixed size n, set up once (allocation at construction), then
/// solve() per problem. H must be symmetric positive semidefinite (rank deficiency allowed).
class BoxQp {
 public:
  virtual ~BoxQp() = default;
  /// Number of variables n.
  virtual int size() const = 0;
  /// Solves the QP; H (n x n, symmetric PSD), g, lower, upper (n) finite with lower <= upper, else
  /// std::invalid_argument naming the argument (detail::check_box_qp: H symmetric to 1e-10 of its largest
  /// |entry|, PSD to n 1e-12 of its largest diagonal entry). Numerical failure is reported in the status,
  /// not thrown.
  virtual QpResult solve(const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                         const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper) = 0;
  /// Minimiser of the last solve (n); meaningful when the last result was ok().
  virtual const VecX& x() const = 0;
  /// Short solver name ("proxsuite-dense", ...).
  virtual std::string name() const = 0;
  /// An independent solver that solves every later problem as this one would (same size, settings and any
  /// state the result depends on), or null when the solver cannot be copied. BiasEstimator and QpBiasEkf
  /// copy their solver through it (the Monte Carlo runner copies a tracker per worker). Not pure, so
  /// solvers written before it still compile; theirs return null and the trackers holding them stay
  /// move-only in effect (copying throws).
  virtual std::unique_ptr<BoxQp> clone() const { return nullptr; }
};

/// q.clone(), or std::invalid_argument naming the solver when it cannot be copied (clone() returns null).
inline std::unique_ptr<BoxQp> clone_box_qp(const BoxQp& q) {
  std::unique_ptr<BoxQp> c = q.clone();
  if (!c)
    throw std::invalid_argument("solver: the BoxQp '" + q.name() +
                                "' cannot be copied (its clone() returns null); give each copy its own "
                                "solver instead");
  return c;
}

/// Owns a BoxQp and copies it through BoxQp::clone(): what lets BiasEstimator and QpBiasEkf be copied.
/// Copying a solver whose clone() returns null throws std::invalid_argument naming it (and, assigned,
/// leaves the target unchanged).
class BoxQpHandle {
 public:
  BoxQpHandle() = default;
  explicit BoxQpHandle(std::unique_ptr<BoxQp> p) : p_(std::move(p)) {}
  BoxQpHandle(const BoxQpHandle& o) : p_(clone_of(o)) {}
  BoxQpHandle& operator=(const BoxQpHandle& o) {
    if (this != &o) p_ = clone_of(o);  // cloned before p_ changes
    return *this;
  }
  BoxQpHandle(BoxQpHandle&&) noexcept = default;
  BoxQpHandle& operator=(BoxQpHandle&&) noexcept = default;
  ~BoxQpHandle() = default;

  BoxQp& operator*() const { return *p_; }
  BoxQp* operator->() const { return p_.get(); }
  explicit operator bool() const { return p_ != nullptr; }

 private:
  static std::unique_ptr<BoxQp> clone_of(const BoxQpHandle& o) {
    return o.p_ ? clone_box_qp(*o.p_) : nullptr;
  }
  std::unique_ptr<BoxQp> p_;
};

/// A BoxQp that never solves (status kFailed, x = 0): the stand-in when no solver is compiled in, and the
/// way tests exercise the callers' QP-failure fallback.
class FailingBoxQp final : public BoxQp {
 public:
  explicit FailingBoxQp(int n) : n_(n) {
    NLOSLOC_ENSURE(n >= 1, "n: expected >= 1 variables, got " + std::to_string(n));
    x_.setZero(n);
    work_.setZero(n, n);
    perm_.setZero(n);
  }
  int size() const override { return n_; }
  std::string name() const override { return "failing"; }
  const VecX& x() const override { return x_; }
  std::unique_ptr<BoxQp> clone() const override { return std::make_unique<FailingBoxQp>(*this); }
  /// Checks the arguments as the other solvers do, then fails.
  QpResult solve(const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                 const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper) override;

 private:
  int n_;
  VecX x_;
  MatX work_;   ///< scratch of the H check (n x n)
  VecXi perm_;  ///< scratch of the H check (n)
};

namespace detail {

/// Symmetry check shared by the box QP's H and BiasEstimator's D (square and finite already checked):
/// std::invalid_argument "<name>: expected a symmetric matrix, got <name>[i,j] = a != <name>[j,i] = b" for
/// the most asymmetric pair when |a - b| > 1e-10 max|entry| (the round-off of A^T A passes). No allocation.
template <class D>
void ensure_symmetric(const Eigen::MatrixBase<D>& A, const char* name) {
  const Eigen::Index n = A.rows();
  double amax = 0.0, worst = 0.0;
  Eigen::Index wi = 0, wj = 0;
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) {
      amax = std::max(amax, std::abs(A(i, j)));
      const double d = std::abs(A(i, j) - A(j, i));
      if (i < j && d > worst) {
        worst = d;
        wi = i;
        wj = j;
      }
    }
  if (worst > 1e-10 * amax) {
    const std::string nm(name);
    const auto at = [&](Eigen::Index i, Eigen::Index j) {
      return nm + "[" + std::to_string(i) + "," + std::to_string(j) +
             "] = " + nlosloc::detail::fmt_shortest(A(i, j));
    };
    nlosloc::detail::throw_invalid_argument(nm + ": expected a symmetric matrix, got " + at(wi, wj) +
                                            " != " + at(wj, wi));
  }
}

/// Where a symmetric matrix fails to be positive semidefinite: the negative curvature found and its rows
/// (row2 < 0 when one row); ok when none.
struct SemidefiniteDefect {
  bool ok = true;
  double curvature = 0.0;
  Eigen::Index row = -1, row2 = -1;
};

/// Positive semidefiniteness of the symmetric part of A (n x n, finite) by a diagonally pivoted Cholesky
/// (outer-product form, largest remaining diagonal first): every pivot must be > tol, and once the largest
/// remaining one is <= tol the remaining Schur complement must vanish to tol (a PSD one has |S_ij| <=
/// sqrt(S_ii S_jj)), so rank-deficient PSD matrices (zero rows, 0, rank 1) pass. A negative remaining
/// diagonal, or a remaining 2 x 2 block [S_ii S_ij; S_ij S_jj] with |S_ij| > tol, is negative curvature
/// (the block's smaller eigenvalue, reported). work (at least n x n) and perm (at least n) are scratch,
/// resized to n here: pass storage sized beforehand (or of fixed capacity) and nothing is allocated.
template <class D, class W, class P>
SemidefiniteDefect semidefinite_defect(const Eigen::MatrixBase<D>& A, double tol, W& work, P& perm) {
  const Eigen::Index n = A.rows();
  work.resize(n, n);
  perm.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    perm[j] = static_cast<typename P::Scalar>(j);
    for (Eigen::Index i = 0; i < n; ++i) work(i, j) = 0.5 * (A(i, j) + A(j, i));
  }
  SemidefiniteDefect res;
  for (Eigen::Index k = 0; k < n; ++k) {
    Eigen::Index p = k;
    for (Eigen::Index i = k + 1; i < n; ++i)
      if (work(i, i) > work(p, p)) p = i;
    if (!(work(p, p) > tol)) {
      // No curvature left above tol: the remaining Schur complement must vanish (PSD) to tol.
      for (Eigen::Index j = k; j < n; ++j)
        for (Eigen::Index i = j; i < n; ++i) {
          const double a = work(i, i), b = work(j, j), c = work(i, j);
          if (i == j ? a < -tol : std::abs(c) > tol) {
            res.ok = false;
            res.curvature = i == j ? a : 0.5 * (a + b) - std::hypot(0.5 * (a - b), c);
            res.row = std::min(perm[i], perm[j]);
            res.row2 = i == j ? -1 : std::max(perm[i], perm[j]);
            return res;
          }
        }
      return res;
    }
    if (p != k) {  // symmetric permutation: rows and columns k <-> p
      work.row(k).swap(work.row(p));
      work.col(k).swap(work.col(p));
      std::swap(perm[k], perm[p]);
    }
    const double d = work(k, k);
    for (Eigen::Index j = k + 1; j < n; ++j) {
      const double f = work(k, j) / d;
      for (Eigen::Index i = k + 1; i < n; ++i) work(i, j) -= work(i, k) * f;
    }
  }
  return res;
}

/// H of the box QP: symmetric (ensure_symmetric) and positive semidefinite to tol = n 1e-12 max(diag H)
/// (semidefinite_defect), the contract of Ke & Wu eq. (14)'s convex QP (with an indefinite H a solver's
/// stationary point is not the minimum on the box). std::invalid_argument naming H otherwise.
template <class W, class P>
void check_box_qp_hessian(const Eigen::Ref<const MatX>& H, W& work, P& perm) {
  ensure_symmetric(H, "H");
  const Eigen::Index n = H.rows();
  double dmax = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) dmax = std::max(dmax, H(i, i));
  const SemidefiniteDefect d = semidefinite_defect(H, static_cast<double>(n) * 1e-12 * dmax, work, perm);
  if (!d.ok)
    nlosloc::detail::throw_invalid_argument(
        "H: expected a positive semidefinite matrix, got negative curvature " +
        nlosloc::detail::fmt_shortest(d.curvature) +
        (d.row2 < 0 ? " at row " + std::to_string(d.row)
                    : " at rows " + std::to_string(d.row) + ", " + std::to_string(d.row2)) +
        " (pivoted Cholesky)");
}

/// Argument checks shared by the implementations: shapes, finite values, lower <= upper, and H symmetric
/// PSD (check_box_qp_hessian, with the caller's scratch work and perm: no allocation when sized already).
template <class W, class P>
void check_box_qp(int n, const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                  const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper, W& work,
                  P& perm) {
  nlosloc::detail::ensure_shape(H, n, n, "H");
  nlosloc::detail::ensure_shape(g, n, 1, "g");
  nlosloc::detail::ensure_shape(lower, n, 1, "lower");
  nlosloc::detail::ensure_shape(upper, n, 1, "upper");
  nlosloc::detail::ensure_finite(H, "H");
  nlosloc::detail::ensure_finite(g, "g");
  nlosloc::detail::ensure_finite(lower, "lower");
  nlosloc::detail::ensure_finite(upper, "upper");
  for (int i = 0; i < n; ++i)
    if (lower[i] > upper[i])
      nlosloc::detail::throw_invalid_argument("lower, upper: expected lower <= upper, got lower[" +
                                              std::to_string(i) + "] = " + std::to_string(lower[i]) +
                                              " > upper[" + std::to_string(i) +
                                              "] = " + std::to_string(upper[i]));
  check_box_qp_hessian(H, work, perm);
}
/// check_box_qp with scratch of its own (allocates): for solvers outside the per-step hot paths.
inline void check_box_qp(int n, const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                         const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper) {
  MatX work;
  VecXi perm;
  check_box_qp(n, H, g, lower, upper, work, perm);
}
inline void check_box_qp_settings(const BoxQpSettings& s) {
  nlosloc::detail::ensure_positive(s.eps_abs, "settings.eps_abs");
  nlosloc::detail::ensure_positive(s.eps_duality_gap_abs, "settings.eps_duality_gap_abs");
  NLOSLOC_ENSURE(s.max_iter >= 1, "settings.max_iter: expected >= 1, got " + std::to_string(s.max_iter));
}
}  // namespace detail

inline QpResult FailingBoxQp::solve(const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                                    const Eigen::Ref<const VecX>& lower,
                                    const Eigen::Ref<const VecX>& upper) {
  detail::check_box_qp(n_, H, g, lower, upper, work_, perm_);
  QpResult r;
  r.status = QpStatus::kFailed;
  r.objective = std::nan("");
  return r;
}

}  // namespace nlosloc::mitigation
