#pragma once
/// \file box_qp_proxsuite.hpp
/// BoxQp on proxsuite's dense QP (proxqp::dense::QP with native box constraints), and make_box_qp(), the
/// general-purpose default (proxsuite, else EnumerationBoxQp of box_qp_enumeration.hpp up to 8 variables).
/// The proxsuite part compiles only when NLOSLOC_HAVE_PROXSUITE is defined (link nlosloc::qp); without it
/// make_proxsuite_box_qp() throws.
///
/// Settings follow DESIGN.md's proxsuite notes: check_duality_gap = true and eps_duality_gap_abs = 1e-9
/// (default tolerances stop ~1e-5 away on rank-deficient box least squares), and every solve re-initialises
/// the problem with init() (solve() again without update() on native box constraints ran to max_iter).
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "nlosloc/mitigation/box_qp.hpp"
#include "nlosloc/mitigation/box_qp_enumeration.hpp"

#ifdef NLOSLOC_HAVE_PROXSUITE
#include <proxsuite/proxqp/dense/dense.hpp>
#endif

namespace nlosloc::mitigation {

#ifdef NLOSLOC_HAVE_PROXSUITE
/// proxsuite dense QP behind the BoxQp interface: n variables, no equality or general inequality rows,
/// native box constraints. The solver object (and its workspace) is built once at construction.
class ProxsuiteBoxQp final : public BoxQp {
 public:
  /// n >= 1 variables; settings validated (std::invalid_argument naming the field).
  explicit ProxsuiteBoxQp(int n, const BoxQpSettings& settings = {})
      : n_(check_n(n)), settings_(settings), qp_(n, 0, 0, true) {
    detail::check_box_qp_settings(settings);
    x_.setZero(n);
    Hx_.setZero(n);
    work_.setZero(n, n);
    perm_.setZero(n);
    auto& s = qp_.settings;
    s.eps_abs = settings.eps_abs;
    s.eps_rel = 0.0;
    s.max_iter = settings.max_iter;
    s.check_duality_gap = settings.check_duality_gap;
    s.eps_duality_gap_abs = settings.eps_duality_gap_abs;
    s.eps_duality_gap_rel = 0.0;
    s.verbose = false;
    s.compute_timings = false;
    s.initial_guess = proxsuite::proxqp::InitialGuessStatus::NO_INITIAL_GUESS;
  }

  int size() const override { return n_; }
  std::string name() const override { return "proxsuite-dense"; }
  const VecX& x() const override { return x_; }
  /// A fresh solver with the same settings and last minimiser: every solve re-initialises proxsuite
  /// without an initial guess, so nothing else carries over from one problem to the next.
  std::unique_ptr<BoxQp> clone() const override {
    auto c = std::make_unique<ProxsuiteBoxQp>(n_, settings_);
    c->x_ = x_;
    c->Hx_ = Hx_;
    return c;
  }
  const BoxQpSettings& settings() const { return settings_; }

  QpResult solve(const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                 const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper) override {
    // H symmetric PSD checked on scratch sized here: proxsuite reads only one triangle of H and would
    // report an indefinite problem as solved at a stationary point (not the minimum on the box).
    detail::check_box_qp(n_, H, g, lower, upper, work_, perm_);
    QpResult res;
    res.objective = std::nan("");
#ifdef EIGEN_RUNTIME_NO_MALLOC
    // proxsuite's dense init/solve allocate (Eigen temporaries) on every call, which is why QpBiasEkf's
    // default solver is EnumerationBoxQp (README). Lifted here only, so the no-malloc test checks the rest.
    struct AllowMalloc {
      bool was = Eigen::internal::is_malloc_allowed();
      AllowMalloc() { Eigen::internal::set_is_malloc_allowed(true); }
      ~AllowMalloc() { Eigen::internal::set_is_malloc_allowed(was); }
    } allow_malloc;
#endif
    try {
      // Re-initialised every time (DESIGN.md): H, g and the box change from one problem to the next.
      qp_.init(H, g, proxsuite::nullopt, proxsuite::nullopt, proxsuite::nullopt, proxsuite::nullopt,
               proxsuite::nullopt, lower, upper, settings_.compute_preconditioner);
      qp_.solve();
    } catch (const std::exception&) {
      res.status = QpStatus::kFailed;
      return res;
    }
    using proxsuite::proxqp::QPSolverOutput;
    const auto& info = qp_.results.info;
    res.iterations = static_cast<int>(info.iter);
    switch (info.status) {
      case QPSolverOutput::PROXQP_SOLVED: res.status = QpStatus::kSolved; break;
      case QPSolverOutput::PROXQP_MAX_ITER_REACHED: res.status = QpStatus::kMaxIterations; break;
      case QPSolverOutput::PROXQP_PRIMAL_INFEASIBLE:
      case QPSolverOutput::PROXQP_SOLVED_CLOSEST_PRIMAL_FEASIBLE:
        res.status = QpStatus::kPrimalInfeasible;
        break;
      case QPSolverOutput::PROXQP_DUAL_INFEASIBLE: res.status = QpStatus::kDualInfeasible; break;
      default: res.status = QpStatus::kFailed;
    }
    x_ = qp_.results.x;
    if (!x_.allFinite()) {
      res.status = QpStatus::kFailed;
      x_.setZero();
      return res;
    }
    // The solver meets the box to its tolerance; project so callers see exactly lower <= x <= upper.
    x_ = x_.cwiseMax(lower).cwiseMin(upper);
    Hx_.noalias() = H * x_;
    res.objective = 0.5 * x_.dot(Hx_) + g.dot(x_);
    return res;
  }

 private:
  static int check_n(int n) {
    NLOSLOC_ENSURE(n >= 1, "n: expected >= 1 variables, got " + std::to_string(n));
    return n;
  }
  int n_;
  BoxQpSettings settings_;
  proxsuite::proxqp::dense::QP<double> qp_;
  VecX x_, Hx_;
  MatX work_;   ///< scratch of the H check (n x n)
  VecXi perm_;  ///< scratch of the H check (n)
};
#endif

/// True when proxsuite was found at build time (ProxsuiteBoxQp exists).
inline constexpr bool have_proxsuite_box_qp() {
#ifdef NLOSLOC_HAVE_PROXSUITE
  return true;
#else
  return false;
#endif
}

/// True: make_box_qp always has a solver for n <= 8 (proxsuite when compiled in, else EnumerationBoxQp).
inline constexpr bool have_default_box_qp() { return true; }

/// proxsuite's dense QP as a BoxQp of size n; std::runtime_error when nlosloc was built without proxsuite.
inline std::unique_ptr<BoxQp> make_proxsuite_box_qp(int n, const BoxQpSettings& settings = {}) {
#ifdef NLOSLOC_HAVE_PROXSUITE
  return std::make_unique<ProxsuiteBoxQp>(n, settings);
#else
  (void)n;
  (void)settings;
  throw std::runtime_error(
      "make_proxsuite_box_qp: nlosloc was built without proxsuite (link nlosloc::qp, or use "
      "EnumerationBoxQp for n <= 8)");
#endif
}

/// The general-purpose BoxQp of size n: proxsuite's dense QP when compiled in, else EnumerationBoxQp
/// (n <= 8; std::runtime_error naming n above). On a rank-deficient H the minimiser is not unique and the
/// two pick different ones (proxsuite's proximal iterations from 0 land near the least-norm one, the
/// enumeration on a vertex of the optimal set), which changes what Ke & Wu's Sec. 3 snapshot form
/// (rank M - 2) returns; so proxsuite stays the default here, and QpBiasEkf takes the enumeration only
/// for its positive definite prediction-referenced QP.
inline std::unique_ptr<BoxQp> make_box_qp(int n, const BoxQpSettings& settings = {}) {
  if (have_proxsuite_box_qp() || n < 1) return make_proxsuite_box_qp(n, settings);
  if (n > EnumerationBoxQp::kMaxVariables)
    throw std::runtime_error("make_box_qp: n = " + std::to_string(n) +
                             " variables needs proxsuite (the enumeration solver takes n <= 8), and nlosloc "
                             "was built without it; pass a BoxQp of your own");
  return std::make_unique<EnumerationBoxQp>(n, settings);
}

}  // namespace nlosloc::mitigation
