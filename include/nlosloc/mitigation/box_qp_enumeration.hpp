#pragma once
/// \file box_qp_enumeration.hpp
/// EnumerationBoxQp: an exact solver for the small box QPs of Ke & Wu eq. (14) (one variable per anchor),
///     minimise 1/2 x^T H x + g^T x   subject to   lower <= x <= upper,   H symmetric PSD,
/// that allocates nothing after construction (proxsuite's dense QP allocates inside every solve, which
/// broke the library's no-allocation rule for QpBiasEkf's step). H is checked (detail::check_box_qp, on
/// fixed-capacity scratch): a non-symmetric or indefinite H throws std::invalid_argument naming H, since
/// the KKT search below is exact only for a convex problem.
///
/// Method: the problem is convex, so x is a global minimiser iff it satisfies the KKT conditions: with
/// grad = H x + g, each variable is free (lower < x_i < upper, grad_i = 0), at its lower bound
/// (grad_i >= 0) or at its upper bound (grad_i <= 0). Each assignment of the variables to {free, lower,
/// upper} fixes the bounded ones, and the free ones solve H_FF x_F = -(g_F + H_FB x_B). An assignment whose
/// solution lies in the box and whose gradient has the right signs is optimal. One with H_FF nonsingular
/// always exists: take a vertex of the (polyhedral) optimal set; a v != 0 with H_FF v = 0 would give
/// v^T H v = 0 on F, hence H v = 0 (H PSD), a direction along which the vertex could move within the
/// optimal set. So assignments whose H_FF is singular (a Cholesky pivot below 1e-12 of its largest diagonal)
/// are skipped, and the search over all 3^n assignments is exhaustive: it starts from the last solve's
/// assignment (consecutive tracker steps mostly share it), then goes through the others in order. The cost
/// bounds n: at most kMaxVariables = 8 (6561 assignments, about a millisecond in the worst case; Ke & Wu's
/// scenarios have 3 and 4 anchors and a typical solve tries a few).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "nlosloc/mitigation/box_qp.hpp"

namespace nlosloc::mitigation {

class EnumerationBoxQp final : public BoxQp {
 public:
  static constexpr int kMaxVariables = 8;

  /// 1 <= n <= kMaxVariables; settings validated (std::invalid_argument naming the field). eps_abs is the
  /// tolerance of the KKT checks (bounds and gradient signs, relative to the problem's scale).
  explicit EnumerationBoxQp(int n, const BoxQpSettings& settings = {}) : n_(check_n(n)), settings_(settings) {
    detail::check_box_qp_settings(settings);
    x_.setZero(n);
    last_.fill(0);
  }

  int size() const override { return n_; }
  std::string name() const override { return "enumeration"; }
  const VecX& x() const override { return x_; }
  /// A copy, the last active set included (the search starts from it, and on a singular H the vertex
  /// returned can depend on it).
  std::unique_ptr<BoxQp> clone() const override { return std::make_unique<EnumerationBoxQp>(*this); }
  const BoxQpSettings& settings() const { return settings_; }

  /// The active set the next solve tries first (the last successful solve's): per variable 0 = free,
  /// 1 = at its lower bound, 2 = at its upper bound. With set_active_set, what saving a solver needs (the
  /// Python bindings pickle it) so that the restored one solves every later problem as this one would.
  std::vector<int> active_set() const {
    std::vector<int> a(static_cast<std::size_t>(n_));
    for (int i = 0; i < n_; ++i) a[static_cast<std::size_t>(i)] = last_[static_cast<std::size_t>(i)];
    return a;
  }
  /// Sets the active set tried first; std::invalid_argument naming `active_set` unless it has size()
  /// entries in {0, 1, 2} (the solver is then unchanged).
  void set_active_set(const std::vector<int>& a) {
    NLOSLOC_ENSURE(a.size() == static_cast<std::size_t>(n_), "active_set: expected " + std::to_string(n_) +
                                                                 " entries, got " + std::to_string(a.size()));
    for (std::size_t i = 0; i < a.size(); ++i)
      NLOSLOC_ENSURE(a[i] >= 0 && a[i] <= 2,
                     "active_set: expected entries 0 (free), 1 (lower) or 2 (upper), got " +
                         std::to_string(a[i]) + " at " + std::to_string(i));
    for (std::size_t i = 0; i < a.size(); ++i) last_[i] = static_cast<std::uint8_t>(a[i]);
  }

  QpResult solve(const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                 const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper) override {
    detail::check_box_qp(n_, H, g, lower, upper, work_, perm_);  // fixed-capacity scratch: no allocation
    QpResult res;
    res.objective = std::nan("");
    // Scale of the KKT tolerances: the gradient's and the box's magnitudes.
    double hmax = 0.0, gmax = 0.0, bmax = 0.0;
    for (int i = 0; i < n_; ++i) {
      gmax = std::max(gmax, std::abs(g[i]));
      bmax = std::max({bmax, std::abs(lower[i]), std::abs(upper[i])});
      for (int j = 0; j < n_; ++j) hmax = std::max(hmax, std::abs(H(i, j)));
    }
    const double tol_x = settings_.eps_abs * (1.0 + bmax);
    const double tol_g = settings_.eps_abs * (1.0 + gmax + hmax * bmax);

    std::int64_t total = 1;
    for (int i = 0; i < n_; ++i) total *= 3;
    Assignment a = last_;
    int tried = 0;
    // The last solve's assignment first, then every assignment in base-3 order (skipping that one).
    for (std::int64_t code = -1; code < total; ++code) {
      if (code >= 0) {
        decode(code, a);
        if (a == last_) continue;
      }
      ++tried;
      if (try_assignment(a, H, g, lower, upper, tol_x, tol_g)) {
        last_ = a;
        res.status = QpStatus::kSolved;
        res.iterations = tried;
        res.objective = objective(H, g);
        return res;
      }
    }
    // No assignment passed the checks: only numerical trouble (a nearly singular H_FF) gets here.
    x_.setZero();
    res.status = QpStatus::kFailed;
    res.iterations = tried;
    return res;
  }

 private:
  enum Where : std::uint8_t { kFree = 0, kLower = 1, kUpper = 2 };
  using Assignment = std::array<std::uint8_t, kMaxVariables>;
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxVariables, kMaxVariables>;
  using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxVariables, 1>;

  static int check_n(int n) {
    NLOSLOC_ENSURE(n >= 1 && n <= kMaxVariables, "n: expected 1 <= n <= " + std::to_string(kMaxVariables) +
                                                     " variables for the enumeration solver, got " +
                                                     std::to_string(n));
    return n;
  }

  /// 1/2 x^T H x + g^T x at x_, by loops (an Eigen product with the dynamic H would allocate).
  double objective(const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g) const {
    double f = 0.0;
    for (int i = 0; i < n_; ++i) {
      double hx = 0.0;
      for (int j = 0; j < n_; ++j) hx += H(i, j) * x_[j];
      f += x_[i] * (0.5 * hx + g[i]);
    }
    return f;
  }

  void decode(std::int64_t code, Assignment& a) const {
    for (int i = 0; i < n_; ++i) {
      a[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(code % 3);
      code /= 3;
    }
  }

  /// Solves for the free variables of assignment a and checks the KKT conditions; on success x_ holds x.
  bool try_assignment(const Assignment& a, const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                      const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper, double tol_x,
                      double tol_g) {
    int nf = 0;
    for (int i = 0; i < n_; ++i) {
      const auto w = a[static_cast<std::size_t>(i)];
      if (w == kFree) {
        free_[static_cast<std::size_t>(nf++)] = i;
      } else {
        xs_[i] = w == kLower ? lower[i] : upper[i];
      }
    }
    if (nf > 0) {
      // H_FF and the right-hand side -(g_F + H_FB x_B).
      L_.resize(nf, nf);
      rhs_.resize(nf);
      double dmax = 0.0;
      for (int r = 0; r < nf; ++r) {
        const int i = free_[static_cast<std::size_t>(r)];
        double s = -g[i];
        for (int j = 0; j < n_; ++j)
          if (a[static_cast<std::size_t>(j)] != kFree) s -= H(i, j) * xs_[j];
        rhs_[r] = s;
        for (int c = 0; c < nf; ++c) L_(r, c) = H(i, free_[static_cast<std::size_t>(c)]);
        dmax = std::max(dmax, L_(r, r));
      }
      // Cholesky H_FF = L L^T in place (lower triangle); a pivot below 1e-12 dmax: singular, skip.
      // Written out: Eigen's LLT on the same fixed-capacity storage made QpBiasEkf's K1 step 10-20%
      // slower (nlosloc-micro --benchmark_filter='BM_K1Step<Proposed>', 2026-12-05: 322-341 -> 363-385
      // ns with 3 LOS, 415-434 -> 481-493 ns with 3 NLOS).
      const double floor = 1e-12 * dmax;
      if (!(dmax > 0.0)) return false;
      for (int k = 0; k < nf; ++k) {
        double d = L_(k, k);
        for (int m = 0; m < k; ++m) d -= L_(k, m) * L_(k, m);
        if (!(d > floor)) return false;
        const double lkk = std::sqrt(d);
        L_(k, k) = lkk;
        for (int r = k + 1; r < nf; ++r) {
          double s = L_(r, k);
          for (int m = 0; m < k; ++m) s -= L_(r, m) * L_(k, m);
          L_(r, k) = s / lkk;
        }
      }
      for (int r = 0; r < nf; ++r) {  // L y = rhs
        double s = rhs_[r];
        for (int m = 0; m < r; ++m) s -= L_(r, m) * rhs_[m];
        rhs_[r] = s / L_(r, r);
      }
      for (int r = nf - 1; r >= 0; --r) {  // L^T x = y
        double s = rhs_[r];
        for (int m = r + 1; m < nf; ++m) s -= L_(m, r) * rhs_[m];
        rhs_[r] = s / L_(r, r);
      }
      for (int r = 0; r < nf; ++r) {
        const int i = free_[static_cast<std::size_t>(r)];
        const double v = rhs_[r];
        if (!std::isfinite(v) || v < lower[i] - tol_x || v > upper[i] + tol_x) return false;
        xs_[i] = std::min(std::max(v, lower[i]), upper[i]);  // within tolerance: onto the box exactly
      }
    }
    // Gradient signs on the bounded variables.
    for (int i = 0; i < n_; ++i) {
      const auto w = a[static_cast<std::size_t>(i)];
      if (w == kFree) continue;
      double grad = g[i];
      for (int j = 0; j < n_; ++j) grad += H(i, j) * xs_[j];
      if (w == kLower && grad < -tol_g && lower[i] < upper[i]) return false;
      if (w == kUpper && grad > tol_g && lower[i] < upper[i]) return false;
    }
    x_ = xs_.head(n_);
    return true;
  }

  int n_;
  BoxQpSettings settings_;
  VecX x_;
  Eigen::Matrix<double, kMaxVariables, 1> xs_ = Eigen::Matrix<double, kMaxVariables, 1>::Zero();
  Small L_;
  SmallVec rhs_;
  Small work_;                                                       ///< scratch of the H check
  Eigen::Matrix<int, Eigen::Dynamic, 1, 0, kMaxVariables, 1> perm_;  ///< scratch of the H check
  std::array<int, kMaxVariables> free_{};
  Assignment last_{};  ///< the last solve's assignment, tried first
};

}  // namespace nlosloc::mitigation
