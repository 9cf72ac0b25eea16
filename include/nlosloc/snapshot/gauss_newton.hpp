#pragma once
/// \file gauss_newton.hpp
/// Per-epoch (snapshot) position fix on a MeasurementStack: damped Gauss-Newton (Levenberg-Marquardt) on the
/// negative log-likelihood of a subset of rows, each row with a Gaussian or a split (asymmetric) Gaussian
/// noise model. The unknowns theta are the position (D) and, when the stack has RTOA rows, the clock bias
/// tau (Huerta eq. 5 and Table I). This is the MLE-LOS of Huerta Sec. VI-A ("estimates the position only
/// from the observations at the same time iteration, assuming they have been obtained under LOS
/// conditions") and the inner solver of the CHEN, CONG and URR baselines.
///
/// Every row i with residual r_i = y_i - g_i(theta) (wrapped for angle rows) contributes
/// ((r_i - c_i) / s_i)^2 to the cost, s_i = sigma_left when r_i < c_i and sigma_right otherwise. For a
/// Gaussian row c = mean and both sigmas equal its standard deviation (the LOS ML cost); for the split
/// normal of Cong & Zhuang 2005 (noise::AsymmetricNormal) c = mode. The cost is continuously differentiable,
/// so Gauss-Newton with the side picked at the current iterate converges like ordinary least squares.
///
/// Buffers are sized at construction: solve() does not allocate. Not thread-safe (one solver per thread).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "nlosloc/core/types.hpp"
#include "nlosloc/models/measurement.hpp"

namespace nlosloc::snapshot {

/// Unknown vector of a snapshot fix: position (D) then the clock bias (RTOA stacks); at most 4 entries.
using Theta = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;

/// Noise model of one row in a fix: Gaussian (sigma_left == sigma_right) or split normal about `center`.
struct RowNoise {
  double center = 0.0;       ///< mean (Gaussian) or mode (split normal) of the noise
  double sigma_left = 1.0;   ///< standard deviation left of the center (> 0)
  double sigma_right = 1.0;  ///< standard deviation right of the center (> 0)

  /// Gaussian N(mean, std^2): mean finite, std finite > 0.
  static RowNoise gaussian(double mean, double std) {
    const RowNoise r{mean, std, std};
    r.check("RowNoise");
    return r;
  }
  /// Cong & Zhuang 2005 asymmetric (split) Gaussian.
  static RowNoise split(const noise::AsymmetricNormal& a) {
    const RowNoise r{a.mode(), a.sigma_left(), a.sigma_right()};
    r.check("RowNoise");
    return r;
  }
  /// True when center is finite and both sigmas are finite > 0 (a NaN or zero sigma makes the cost NaN
  /// or infinite and the fix meaningless).
  bool valid() const {
    return std::isfinite(center) && sigma_left > 0.0 && std::isfinite(sigma_left) && sigma_right > 0.0 &&
           std::isfinite(sigma_right);
  }
  /// Throws unless valid(); `name` prefixes the field named in the message.
  void check(const std::string& name) const {
    if (!std::isfinite(center))
      detail::throw_invalid_argument(name + ".center: expected a finite value, got " +
                                     std::to_string(center));
    detail::ensure_positive(sigma_left, (name + ".sigma_left").c_str());
    detail::ensure_positive(sigma_right, (name + ".sigma_right").c_str());
  }
  /// Normalised residual (r - c)/s with the side's sigma.
  double normalized(double r) const { return (r - center) / (r < center ? sigma_left : sigma_right); }
  /// Negative log density up to the terms that do not depend on r: 0.5 ((r - c)/s)^2.
  /// log p(r) = log(2/(sqrt(2 pi)(sl + sr))) - 0.5 z^2 (the Gaussian case sl = sr included).
  double log_pdf(double r) const {
    const double z = normalized(r);
    return std::log(2.0 / (sigma_left + sigma_right)) - 0.5 * std::log(2.0 * kPi) - 0.5 * z * z;
  }
};

/// Options of the Gauss-Newton / Levenberg-Marquardt iterations.
struct GaussNewtonOptions {
  int max_iterations = 30;        ///< >= 1
  double step_tolerance = 1e-4;   ///< stop when ||delta theta|| (m, lm) falls below this
  double initial_damping = 1e-6;  ///< Levenberg-Marquardt lambda relative to the normal matrix diagonal
  double max_damping = 1e10;      ///< give up (not converged) beyond this damping
};

/// Result of one fix.
struct Fix {
  Theta theta;                                            ///< position (D) then clock bias if any
  double cost = std::numeric_limits<double>::infinity();  ///< sum of squared normalised residuals
  int rows = 0;                                           ///< rows used
  int iterations = 0;                                     ///< Gauss-Newton iterations taken
  bool converged = false;                                 ///< step tolerance reached with a finite cost
};

/// Bit mask of anchors (anchor b is bit b); the subsets of CHEN, CONG and URR.
using AnchorMask = std::uint32_t;

/// Number of anchors in a mask.
inline int mask_count(AnchorMask m) { return __builtin_popcount(m); }

/// Every anchor mask over B anchors (B <= 20) with at least `min_size` anchors, larger sets first, then
/// ascending mask value (a deterministic order).
inline std::vector<AnchorMask> subsets_at_least(int num_anchors, int min_size) {
  NLOSLOC_ENSURE(num_anchors >= 1 && num_anchors <= 20,
                 "num_anchors: expected 1..20 for subset enumeration, got " + std::to_string(num_anchors));
  std::vector<AnchorMask> v;
  const AnchorMask all = (AnchorMask{1} << num_anchors) - 1;
  for (AnchorMask m = 1; m <= all; ++m)
    if (mask_count(m) >= min_size) v.push_back(m);
  std::stable_sort(v.begin(), v.end(),
                   [](AnchorMask a, AnchorMask b) { return mask_count(a) > mask_count(b); });
  return v;
}

/// Snapshot solver on a MeasurementStack (any rows: TOA, RTOA, TDOA, AOA, AOA phase). The stack must not
/// contain two-way-ranging or linear rows (their unknowns are not position/clock).
class LosSolver {
 public:
  /// `stack`: the scenario's measurement stack (copied). Condition 0 of each row is its LOS noise.
  explicit LosSolver(const MeasurementStack& stack, const GaussNewtonOptions& opt = {})
      : stack_(stack), opt_(opt) {
    NLOSLOC_ENSURE(opt.max_iterations >= 1, "opt.max_iterations: expected >= 1");
    // inf would end every solve after one step, reported converged
    NLOSLOC_ENSURE(std::isfinite(opt.step_tolerance) && opt.step_tolerance > 0.0,
                   "opt.step_tolerance: expected a finite value > 0");
    NLOSLOC_ENSURE(opt.initial_damping >= 0.0 && opt.max_damping > opt.initial_damping,
                   "opt.initial_damping / max_damping: expected 0 <= initial < max");
    stack.check_ready();
    const StateLayout& L = stack.layout();
    has_clock_ = false;
    for (int i = 0; i < stack.rows(); ++i) {
      const RowKind k = stack.row(i).kind;
      NLOSLOC_ENSURE(k != RowKind::kTwrTau && k != RowKind::kTwrT && k != RowKind::kLinear,
                     "stack: row " + std::to_string(i) + " is " + to_string(k) +
                         "; snapshot solvers take TOA, RTOA, TDOA and AOA rows only");
      if (k == RowKind::kRtoa) has_clock_ = true;
    }
    n_ = L.space_dim + (has_clock_ ? 1 : 0);
    const int m = stack.rows();
    x_.setZero(L.dim);
    g_.setZero(m);
    r_.setZero(m);
    J_.setZero(m, L.dim);
    los_.resize(static_cast<std::size_t>(m));
    sight_los_.setZero(stack.num_anchors());
    VecX mean(m);
    MatX cov(m, m);
    stack.noise_moments(x_, sight_los_, mean, cov);  // LOS moments (exact for these row kinds)
    for (int i = 0; i < m; ++i)
      los_[static_cast<std::size_t>(i)] = RowNoise::gaussian(mean[i], std::sqrt(cov(i, i)));
  }

  const MeasurementStack& stack() const { return stack_; }
  /// Number of unknowns: D (+1 with RTOA rows).
  int unknowns() const { return n_; }
  /// True when the clock bias is an unknown (the stack has RTOA rows).
  bool has_clock() const { return has_clock_; }
  /// Space dimension D.
  int space_dim() const { return stack_.layout().space_dim; }
  /// The LOS (condition 0) Gaussian model of every row.
  const std::vector<RowNoise>& los_noise() const { return los_; }
  const GaussNewtonOptions& options() const { return opt_; }

  /// Full state vector (zeros except position and clock bias) of theta.
  template <class DT>
  void to_state(const Eigen::MatrixBase<DT>& theta, VecX& x) const {
    const StateLayout& L = stack_.layout();
    x.setZero(L.dim);
    x.segment(L.position, L.space_dim) = theta.head(L.space_dim);
    if (has_clock_) x[L.clock_bias] = theta[L.space_dim];
  }

  /// Residuals r = y - g(theta) of every row (angle rows wrapped) into `r` (size rows()).
  void residuals(const Eigen::Ref<const VecX>& y, const Theta& theta, VecX& r) const {
    detail::ensure_shape(y, stack_.rows(), 1, "y");
    detail::ensure_shape(theta, n_, 1, "theta");
    set_x(theta);
    stack_.predict(x_, 0.0, g_);
    r = y - g_;
    stack_.wrap_residual(r);
  }

  /// Cost sum_i ((r_i - c_i)/s_i)^2 over the rows with use[i] true (and y finite).
  double cost(const Eigen::Ref<const VecX>& y, const Theta& theta, const std::vector<char>& use,
              const std::vector<RowNoise>& noise) const {
    check_rows(y, use, &noise);
    detail::ensure_shape(theta, n_, 1, "theta");
    return cost_unchecked(y, theta, use, noise);
  }

  /// Fix from the rows with use[i] true (rows whose y is NaN are skipped) with per-row noise models
  /// `noise` (size rows(), each RowNoise::valid()), starting at theta0 (size unknowns()).
  Fix solve(const Eigen::Ref<const VecX>& y, const Theta& theta0, const std::vector<char>& use,
            const std::vector<RowNoise>& noise) const {
    const int m = stack_.rows();
    check_rows(y, use, &noise);
    detail::ensure_shape(theta0, n_, 1, "theta0");
    for (int i = 0; i < m; ++i)  // the name is built only on failure: solve() does not allocate
      if (!noise[static_cast<std::size_t>(i)].valid())
        noise[static_cast<std::size_t>(i)].check("noise[" + std::to_string(i) + "]");
    Fix f;
    f.theta = theta0;
    int rows = 0;
    for (int i = 0; i < m; ++i) rows += use[static_cast<std::size_t>(i)] && !std::isnan(y[i]);
    f.rows = rows;
    if (rows == 0 || !theta0.allFinite()) return f;
    const StateLayout& L = stack_.layout();
    const int D = L.space_dim;
    double cost = eval(y, f.theta, use, noise, true);
    double lambda = opt_.initial_damping;
    for (int it = 0; it < opt_.max_iterations; ++it) {
      f.iterations = it + 1;
      // Normal equations of the weighted residuals z_i = (r_i - c_i)/s_i: (A + lambda diag A) delta = b,
      // A = sum w_i J_i^T J_i, b = sum w_i J_i^T (r_i - c_i), w_i = 1/s_i^2 (Gauss-Newton on the ML cost).
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4> A(n_, n_);
      Theta b(n_), jrow(n_);
      A.setZero();
      b.setZero();
      for (int i = 0; i < m; ++i) {
        if (!use[static_cast<std::size_t>(i)] || std::isnan(y[i])) continue;
        const RowNoise& nz = noise[static_cast<std::size_t>(i)];
        const double s = r_[i] < nz.center ? nz.sigma_left : nz.sigma_right;
        const double w = 1.0 / (s * s);
        for (int k = 0; k < D; ++k) jrow[k] = J_(i, L.position + k);
        if (has_clock_) jrow[D] = J_(i, L.clock_bias);
        A.noalias() += w * jrow * jrow.transpose();
        b.noalias() += w * (r_[i] - nz.center) * jrow;
      }
      bool accepted = false;
      Theta delta(n_);
      while (lambda <= opt_.max_damping) {
        auto Ad = A;
        Ad.diagonal() += lambda * A.diagonal().cwiseMax(1e-12);
        delta = Ad.ldlt().solve(b);
        if (!delta.allFinite()) {
          lambda = std::max(lambda * 10.0, 1e-6);
          continue;
        }
        const Theta trial = f.theta + delta;
        const double c = eval(y, trial, use, noise, false);
        if (c <= cost) {
          f.theta = trial;
          cost = eval(y, f.theta, use, noise, true);  // Jacobian and residuals at the new point
          lambda = std::max(lambda * 0.1, opt_.initial_damping);
          accepted = true;
          break;
        }
        lambda = std::max(lambda * 10.0, 1e-6);
      }
      if (!accepted) {  // no decrease along any damped step: at a minimum to working precision
        f.converged = std::isfinite(cost);
        break;
      }
      if (delta.norm() < opt_.step_tolerance) {
        f.converged = std::isfinite(cost);
        break;
      }
    }
    f.cost = cost;
    return f;
  }

  /// Fix from every row with the LOS Gaussian model (MLE-LOS).
  Fix solve_los(const Eigen::Ref<const VecX>& y, const Theta& theta0) const {
    all_.assign(static_cast<std::size_t>(stack_.rows()), 1);
    return solve(y, theta0, all_, los_);
  }

  /// Row flags of the rows whose anchor (both anchors for TDOA) is in `mask`.
  void rows_of(AnchorMask mask, std::vector<char>& use) const {
    use.assign(static_cast<std::size_t>(stack_.rows()), 0);
    for (int i = 0; i < stack_.rows(); ++i) {
      const MeasurementRow& r = stack_.row(i);
      bool in = r.anchor >= 0 && ((mask >> r.anchor) & 1U);
      if (r.anchor2 >= 0) in = in && ((mask >> r.anchor2) & 1U);
      use[static_cast<std::size_t>(i)] = in ? 1 : 0;
    }
  }

  /// Closed-form linear least-squares start for TOA / RTOA rows with use[i] (NaN skipped), or false when
  /// there are too few such rows (TOA: D + 1, RTOA: D + 2) or the system is singular. Squaring
  /// (y_i - tau)^2 = ||p - q_i||^2 gives rows [2 q_i^T, -2 y_i, 1] [p; tau; tau^2 - ||p||^2] =
  /// ||q_i||^2 - y_i^2 (RTOA, Bancroft-type linearisation) and [2 q_i^T, -1] [p; ||p||^2] = ||q_i||^2 - y_i^2
  /// (TOA); the auxiliary unknown is left free (linear LS of the range-squared differences).
  bool linear_start(const Eigen::Ref<const VecX>& y, const std::vector<char>& use, Theta& theta) const {
    check_rows(y, use, nullptr);
    const int D = space_dim();
    const int nv = has_clock_ ? D + 2 : D + 1;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 5, 5> A(nv, nv);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 5, 1> b(nv), a(nv);
    A.setZero();
    b.setZero();
    int rows = 0;
    for (int i = 0; i < stack_.rows(); ++i) {
      const MeasurementRow& r = stack_.row(i);
      if (!use[static_cast<std::size_t>(i)] || std::isnan(y[i])) continue;
      if (r.kind != RowKind::kToa && r.kind != RowKind::kRtoa) continue;
      const double yi = y[i] - los_[static_cast<std::size_t>(i)].center;
      const auto q = stack_.anchors().row(r.anchor);
      for (int k = 0; k < D; ++k) a[k] = 2.0 * q[k];
      if (has_clock_) {
        a[D] = r.kind == RowKind::kRtoa ? -2.0 * yi : 0.0;
        a[D + 1] = 1.0;
      } else {
        a[D] = -1.0;
      }
      const double rhs = q.squaredNorm() - yi * yi;
      A.noalias() += a * a.transpose();
      b.noalias() += rhs * a;
      ++rows;
    }
    if (rows < nv) return false;
    const auto ldlt = A.ldlt();
    if (ldlt.info() != Eigen::Success) return false;
    const auto sol = ldlt.solve(b).eval();
    if (!sol.allFinite()) return false;
    theta.resize(n_);
    theta.head(D) = sol.head(D);
    if (has_clock_) theta[D] = sol[D];
    return true;
  }

 private:
  /// Sizes of the per-row arguments: y, use and (when given) noise have one entry per row; reading them
  /// row by row without this check runs past the end of a short vector.
  void check_rows(const Eigen::Ref<const VecX>& y, const std::vector<char>& use,
                  const std::vector<RowNoise>* noise) const {
    const auto m = static_cast<std::size_t>(stack_.rows());
    detail::check_measurement(y, stack_.rows());  // NaN = missing row; inf is an error
    NLOSLOC_ENSURE(use.size() == m, "use: expected one flag per row (" + std::to_string(m) + "), got " +
                                        std::to_string(use.size()));
    NLOSLOC_ENSURE(noise == nullptr || noise->size() == m, "noise: expected one RowNoise per row (" +
                                                               std::to_string(m) + "), got " +
                                                               std::to_string(noise ? noise->size() : 0));
  }
  /// cost() without the argument checks (solve() checks them once, then evaluates many times).
  double cost_unchecked(const Eigen::Ref<const VecX>& y, const Theta& theta, const std::vector<char>& use,
                        const std::vector<RowNoise>& noise) const {
    set_x(theta);
    stack_.predict(x_, 0.0, g_);
    r_ = y - g_;
    stack_.wrap_residual(r_);
    double c = 0.0;
    for (int i = 0; i < stack_.rows(); ++i)
      if (use[static_cast<std::size_t>(i)] && !std::isnan(y[i])) {
        const double z = noise[static_cast<std::size_t>(i)].normalized(r_[i]);
        c += z * z;
      }
    return c;
  }
  void set_x(const Theta& theta) const {
    const StateLayout& L = stack_.layout();
    x_.segment(L.position, L.space_dim) = theta.head(L.space_dim);
    if (has_clock_) x_[L.clock_bias] = theta[L.space_dim];
  }
  /// Cost at theta; with `jac` also the Jacobian (J_) at theta. Leaves the residuals in r_.
  double eval(const Eigen::Ref<const VecX>& y, const Theta& theta, const std::vector<char>& use,
              const std::vector<RowNoise>& noise, bool jac) const {
    const double c = cost_unchecked(y, theta, use, noise);
    if (jac) stack_.jacobian(x_, 0.0, J_);
    return std::isfinite(c) ? c : std::numeric_limits<double>::infinity();
  }

  MeasurementStack stack_;
  GaussNewtonOptions opt_;
  bool has_clock_ = false;
  int n_ = 0;
  std::vector<RowNoise> los_;
  VecXi sight_los_;
  mutable VecX x_, g_, r_;
  mutable MatX J_;
  mutable std::vector<char> all_;
};

}  // namespace nlosloc::snapshot
