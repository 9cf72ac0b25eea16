#pragma once
/// \file bias_estimation.hpp
/// Direct NLOS bias estimation of Ke & Wu 2011 Sec. 3 (papers/ke-wu2011-qp-ekf.md), for M TOA ranges
/// z_i = d_i + n_i + b_i (eq. 1) to anchors a_i in 2-D:
///   - reference point X0 = centre of the feasible region of the range discs (Sec. 3), see reference_point();
///   - H0, the Jacobian of the ranges at X0 (eq. 10), and the linearised measurement y = H0 X + n + b (eq. 9)
///     with y = z - f(X0) + H0 X0 (first-order Taylor expansion at X0);
///   - U and the bias-free estimate X~ (eq. 11), the bias metric r and L = I + H0 U (eq. 12);
///   - Sigma_v, the covariance of v (eq. 13), computed as Sigma_v = L R L^T: under the linear model (9),
///     X~ = -U y = X - U n - U b (because -U H0 = I), so X - X^ = U n and v = H0 U n + n = L n;
///   - the box QP of eq. (14) with lower bound 0 and the upper bound of eq. (15), solved through BoxQp.
///
/// Sigma_v = L R L^T has rank M - 2 (L is a projector with L H0 = 0), so eq. (14)'s Sigma_v^-1 does not
/// exist. We use the symmetric generalised inverse Sigma_v^- = R^-1 L (Sigma_v Sigma_v^- Sigma_v = L L L R =
/// Sigma_v, since Sigma_v = L R L^T = L R and L^2 = L); r - L b = L (y - b) lies in the range of Sigma_v,
/// where every generalised inverse gives the same quadratic form, so this *is* eq. (14)'s objective. Its
/// Hessian 2 L^T Sigma_v^- L has rank M - 2 as well: the minimisers form the set {b = y - H0 xi} (the
/// biases implied by a candidate position xi) cut by the box, generally not a single point. The QP solver
/// returns one of them (proxsuite, started cold, returns one close to the minimum-norm minimiser).
///
/// Consequence (measured on K1, issue #4): whatever minimiser is picked, z - b^ are the ranges of one point
/// xi of the feasible region, so the snapshot form only moves the EKF towards some point of that region
/// (min-norm pick: next to the biased least-squares fix). With M = 3 in 2-D the snapshot carries one
/// number about b per step; it cannot separate three biases.
///
/// Second form, estimate_from_innovation() (the trackers' default, QpBiasEkf, BiasReference::kPrediction):
/// eqs. (12)-(14) with the bias-free estimate X~ of eq. (12) read as the tracker's prediction S(k|k-1)
/// (the "estimate X^" of eq. 13 whose error enters v), linearised where the EKF linearises (eq. 19):
///   r = z - f(X(k|k-1)) = alpha(k) (eq. 26),  L = I,  v = F (S - S(k|k-1)) + n,
///   Sigma_v = F P(k|k-1) F^T + R = D_LOS(k) (eq. 27),
///   b^ = argmin (r - b)^T Sigma_v^-1 (r - b)  s.t. 0 <= b_i <= b_i^U (eqs. 14-15).
/// Sigma_v is positive definite, so the minimiser is unique. This is also what eq. (14) becomes when the
/// prior N(S(k|k-1), P(k|k-1)) of the EKF is added to the snapshot objective and the position is
/// eliminated: min over (b, X) of |y - H0 X - b|^2_R^-1 + |X - X(k|k-1)|^2_P^-1 gives the same b^.
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "nlosloc/core/types.hpp"
#include "nlosloc/filters/common.hpp"
#include "nlosloc/mitigation/box_qp.hpp"
#include "nlosloc/mitigation/box_qp_proxsuite.hpp"

namespace nlosloc::mitigation {

/// How the reference point X0 was obtained.
enum class ReferenceKind {
  kFeasibleVertices = 0,  ///< Sec. 3: mean of the vertices of the discs' common region
  kHint = 1,              ///< fallback: the caller's hint (the tracker's predicted position)
  kLeastSquares = 2       ///< fallback without hint: least-squares range fit (Gauss-Newton)
};

/// Residual r and covariance Sigma_v used by eq. (14) in the trackers (file comment).
enum class BiasReference {
  kPrediction = 0,  ///< r = alpha(k) (eq. 26), L = I, Sigma_v = D_LOS(k) (eq. 27): estimate_from_innovation
  kSnapshot = 1     ///< Sec. 3 as written: X0, H0, X~ = LS fix, L, Sigma_v = L R L^T: estimate
};

/// Bits of a bias estimate's / tracker step's `flags` (a fallback was taken; the result stays finite).
enum MitigationFlag : unsigned {
  kFlagNone = 0u,
  /// The range discs have no vertex common to all (inconsistent ranges, or one disc inside all others):
  /// X0 taken from the hint / the least-squares fit instead of Sec. 3's centre of the feasible region.
  kFlagReferenceFallback = 1u << 0,
  /// Eq. (15) gave b_i^U < b_i^L = 0 for some i (ranges z_i + z_j < l_ij, inconsistent): b_i^U set to 0,
  /// i.e. b_i fixed to 0 (those ranges are too short to carry a positive bias).
  kFlagBoundsClamped = 1u << 1,
  /// The QP of eq. (14) was not solved (solver status not "solved", or non-finite output): b^ = 0 (the step
  /// falls back to the plain EKF update, eq. 24).
  kFlagQpFailed = 1u << 2,
  /// H0^T R^-1 H0 singular (reference point on an anchor, or all anchors and X0 collinear): b^ = 0.
  kFlagDegenerateGeometry = 1u << 3,
  /// A range is missing (NaN): no bias estimation this step, b^ = 0 (the tracker skips that row).
  kFlagMissingRows = 1u << 4,
  /// Tracker only: the update produced a non-finite state; the predicted belief was kept instead.
  kFlagUpdateRejected = 1u << 5
};

/// Range noise of the trackers: std_i = sigma0 + relative * d_i (d_i the range at the linearisation point),
/// K1/K2: sigma0 = 50 m (Ke & Wu Sec. 6); K3: relative = 0.02 (Sec. 6.4).
struct RangeNoise {
  double sigma0 = 50.0;   ///< constant part (m), >= 0
  double relative = 0.0;  ///< part proportional to the distance, >= 0
  double min_std = 1e-3;  ///< floor of the std (m), > 0, so R stays positive definite
  /// Noise std at distance d.
  double std_at(double d) const { return std::max(sigma0 + relative * d, min_std); }
  /// Throws std::invalid_argument naming the field.
  void validate(const char* name = "noise") const {
    const std::string n(name);
    nlosloc::detail::ensure_nonnegative(sigma0, (n + ".sigma0").c_str());
    nlosloc::detail::ensure_nonnegative(relative, (n + ".relative").c_str());
    nlosloc::detail::ensure_positive(min_std, (n + ".min_std").c_str());
  }
};

/// Reference point of Sec. 3.
struct ReferencePoint {
  Vec<2> point = Vec<2>::Zero();
  ReferenceKind kind = ReferenceKind::kFeasibleVertices;
  int vertices = 0;  ///< vertices averaged (kFeasibleVertices)
};

namespace detail {
/// Gauss-Newton least-squares range fit min sum_i (||X - a_i|| - z_i)^2 from `start` (fixed iterations).
template <class DA, class DZ>
Vec<2> range_least_squares(const Eigen::MatrixBase<DA>& anchors, const Eigen::MatrixBase<DZ>& z, Vec<2> x,
                           int iterations = 20) {
  const Eigen::Index M = anchors.rows();
  for (int it = 0; it < iterations; ++it) {
    Mat<2, 2> A = Mat<2, 2>::Zero();
    Vec<2> g = Vec<2>::Zero();
    for (Eigen::Index i = 0; i < M; ++i) {
      const Vec<2> d = x - anchors.row(i).transpose();
      const double n = d.norm();
      if (!(n > 1e-12)) continue;
      const Vec<2> h = d / n;
      A.noalias() += h * h.transpose();
      g.noalias() += h * (z[i] - n);
    }
    A.diagonal().array() += 1e-12 * (1.0 + A.trace());  // Levenberg damping: collinear anchors stay solvable
    const Vec<2> step = A.ldlt().solve(g);
    if (!step.allFinite()) break;
    x += step;
    if (step.norm() < 1e-9 * (1.0 + x.norm())) break;
  }
  return x;
}

/// reference_point() without its argument checks: what BiasEstimator::estimate() calls on ranges it has
/// checked itself (finite; a negative range, possible with noise near an anchor, is not an error there).
template <class DA, class DZ>
ReferencePoint reference_point_unchecked(const Eigen::MatrixBase<DA>& anchors, const Eigen::MatrixBase<DZ>& z,
                                         const Vec<2>* hint) {
  const Eigen::Index M = anchors.rows();
  ReferencePoint rp;
  Vec<2> sum = Vec<2>::Zero();
  int count = 0;
  for (Eigen::Index i = 0; i < M; ++i)
    for (Eigen::Index j = i + 1; j < M; ++j) {
      const Vec<2> ai = anchors.row(i).transpose(), aj = anchors.row(j).transpose();
      const Vec<2> d = aj - ai;
      const double l = d.norm();
      if (!(l > 0.0)) continue;
      const double zi = z[i], zj = z[j];
      if (zi + zj < l || std::abs(zi - zj) > l) continue;  // circles i and j do not meet
      const double s = (l * l + zi * zi - zj * zj) / (2.0 * l);
      const double h = std::sqrt(std::max(zi * zi - s * s, 0.0));
      const Vec<2> e = d / l;
      const Vec<2> perp(-e[1], e[0]);
      for (int sign = -1; sign <= 1; sign += 2) {
        if (sign == 1 && h == 0.0) break;  // tangent circles: one point
        const Vec<2> p = ai + s * e + (sign * h) * perp;
        bool inside = true;
        for (Eigen::Index k = 0; k < M && inside; ++k) {
          if (k == i || k == j) continue;
          inside = (p - anchors.row(k).transpose()).norm() <= z[k] + 1e-9 * (1.0 + std::abs(z[k]));
        }
        if (inside) {
          sum += p;
          ++count;
        }
      }
    }
  if (count > 0) {
    rp.point = sum / count;
    rp.kind = ReferenceKind::kFeasibleVertices;
    rp.vertices = count;
    return rp;
  }
  if (hint != nullptr && hint->allFinite()) {
    rp.point = *hint;
    rp.kind = ReferenceKind::kHint;
    return rp;
  }
  const Vec<2> centroid = anchors.colwise().mean().transpose();
  rp.point = range_least_squares(anchors, z, centroid);
  rp.kind = ReferenceKind::kLeastSquares;
  return rp;
}
}  // namespace detail

/// Reference point X0 of Ke & Wu Sec. 3: "the centre of the feasible region" of the discs |X - a_i| <= z_i.
/// Rule implemented: the vertices of the region are the pairwise circle intersection points lying in every
/// other disc (tolerance 1e-9 (1 + z_k)); X0 is their mean (with three nodes the paper's average of the
/// three intersection points). Documented fallback when there is no such vertex (the discs have no common
/// point because ranges are inconsistent, or one disc lies inside all others): X0 = *hint when given (the
/// trackers pass their predicted position), else the least-squares range fit from the anchors' centroid.
/// anchors M x 2 (M >= 2, finite), z M finite ranges >= 0 (m), else std::invalid_argument naming the
/// argument (a NaN or negative range has no disc). No heap allocation.
template <class DA, class DZ>
ReferencePoint reference_point(const Eigen::MatrixBase<DA>& anchors, const Eigen::MatrixBase<DZ>& z,
                               const Vec<2>* hint = nullptr) {
  nlosloc::detail::ensure_shape(anchors, -1, 2, "anchors");
  const Eigen::Index M = anchors.rows();
  NLOSLOC_ENSURE(M >= 2, "anchors: expected at least 2 anchors (rows), got " + std::to_string(M));
  nlosloc::detail::ensure_finite(anchors, "anchors");
  nlosloc::detail::ensure_shape(z, M, 1, "z");
  for (Eigen::Index i = 0; i < M; ++i)
    if (!(z[i] >= 0.0) || !std::isfinite(z[i]))  // Sec. 3: z_i is the radius of disc i
      nlosloc::detail::throw_invalid_argument("z: expected finite ranges >= 0 (m), got " +
                                              nlosloc::detail::fmt_shortest(z[i]) + " at row " +
                                              std::to_string(i));
  return detail::reference_point_unchecked(anchors, z, hint);
}

class QpBiasEkf;

/// Result of one bias estimation (Ke & Wu Sec. 3); sizes M, owned by the BiasEstimator.
struct BiasEstimate {
  VecX bias;                 ///< b^ of eq. (14) (m), finite, in [lower, upper]; 0 when a fallback zeroed it
  VecX lower, upper;         ///< bounds of eq. (14)-(15) after the documented clamp (m)
  ReferencePoint reference;  ///< X0 of Sec. 3
  Vec<2> x_tilde = Vec<2>::Zero();  ///< bias-free estimate X~ of eq. (11) (m)
  QpResult qp;         ///< what the solver reported (status kFailed with 0 iterations when not run)
  unsigned flags = 0;  ///< MitigationFlag bits
};

/// Ke & Wu Sec. 3 for a fixed set of M >= 3 anchors: buffers and the QP solver are set up once at
/// construction; estimate() does not allocate (beyond what the QP solver does inside). A copy gets its own
/// solver through BoxQp::clone() (std::invalid_argument naming the solver when it has none).
class BiasEstimator {
 public:
  /// anchors M x 2 (M >= 3, finite, distinct); solver: a BoxQp of size M (default make_box_qp(M)).
  explicit BiasEstimator(const MatX& anchors, std::unique_ptr<BoxQp> solver = nullptr)
      : anchors_(anchors), M_(static_cast<int>(anchors.rows())) {
    nlosloc::detail::ensure_shape(anchors, -1, 2, "anchors");
    NLOSLOC_ENSURE(M_ >= 3, "anchors: expected at least 3 anchors (rows), got " + std::to_string(M_));
    nlosloc::detail::ensure_finite(anchors, "anchors");
    solver_ = BoxQpHandle(solver ? std::move(solver) : make_box_qp(M_));
    NLOSLOC_ENSURE(solver_->size() == M_, "solver: expected a BoxQp of size " + std::to_string(M_) +
                                              " (one variable per anchor), got " +
                                              std::to_string(solver_->size()));
    l_.setZero(M_, M_);
    for (int i = 0; i < M_; ++i)
      for (int j = 0; j < M_; ++j) {
        l_(i, j) = (anchors_.row(i) - anchors_.row(j)).norm();
        NLOSLOC_ENSURE(i == j || l_(i, j) > 0.0,
                       "anchors: rows " + std::to_string(i) + " and " + std::to_string(j) + " coincide");
      }
    H0_.setZero(M_, 2);
    U_.setZero(2, M_);
    L_.setZero(M_, M_);
    Sv_.setZero(M_, M_);
    Svg_.setZero(M_, M_);
    T_.setZero(M_, M_);
    Hq_.setZero(M_, M_);
    gq_.setZero(M_);
    y_.setZero(M_);
    r_.setZero(M_);
    rinv_.setZero(M_);
    lq_.setZero(M_);
    uq_.setZero(M_);
    tmp_.setZero(M_);
    est_.bias.setZero(M_);
    est_.lower.setZero(M_);
    est_.upper.setZero(M_);
    save();  // sizes the backup once: later saves copy without allocating
  }

  BiasEstimator(const BiasEstimator&) = default;
  BiasEstimator(BiasEstimator&&) noexcept = default;
  BiasEstimator& operator=(BiasEstimator&&) noexcept = default;
  /// Copy and swap: a solver that cannot be cloned leaves this estimator unchanged.
  BiasEstimator& operator=(const BiasEstimator& o) {
    if (this != &o) *this = BiasEstimator(o);
    return *this;
  }
  ~BiasEstimator() = default;

  int size() const { return M_; }
  const MatX& anchors() const { return anchors_; }
  const BoxQp& solver() const { return *solver_; }

  /// Estimates the NLOS biases of ranges z (M, NaN = missing) with noise variances `variances` (M, > 0:
  /// the diagonal of R). `hint` (optional): position used when the discs have no common vertex (see
  /// reference_point). Never throws on inconsistent data: fallbacks are flagged in the result. A solver
  /// that throws leaves the estimator as it was (last estimate and intermediates).
  const BiasEstimate& estimate(const Eigen::Ref<const VecX>& z, const Eigen::Ref<const VecX>& variances,
                               const Vec<2>* hint = nullptr) {
    nlosloc::detail::check_measurement(z, M_, "z");  // before est_ changes
    nlosloc::detail::ensure_shape(variances, M_, 1, "variances");
    for (int i = 0; i < M_; ++i)
      NLOSLOC_ENSURE(variances[i] > 0.0 && std::isfinite(variances[i]),
                     "variances: expected finite values > 0, got " + std::to_string(variances[i]) +
                         " at row " + std::to_string(i));
    save();  // same sizes: no allocation
    BiasEstimate& e = est_;
    e.flags = 0;
    e.bias.setZero();
    e.qp = QpResult{};
    if (z.hasNaN()) e.flags |= kFlagMissingRows;
    if (e.flags & kFlagMissingRows) {
      e.lower.setZero();
      e.upper.setZero();
      return e;
    }

    // Sec. 3: reference point X0, centre of the feasible region (documented fallback in reference_point).
    e.reference = detail::reference_point_unchecked(anchors_, z, hint);
    if (e.reference.kind != ReferenceKind::kFeasibleVertices) e.flags |= kFlagReferenceFallback;
    const Vec<2> x0 = e.reference.point;

    // Eq. (10): H0, Jacobian of f at X0; eq. (9): y = z - f(X0) + H0 X0.
    for (int i = 0; i < M_; ++i) {
      const Vec<2> d = x0 - anchors_.row(i).transpose();
      const double n = d.norm();
      if (!(n > 1e-9 * (1.0 + l_.maxCoeff()))) {
        e.flags |= kFlagDegenerateGeometry;
        e.lower.setZero();
        e.upper.setZero();
        return e;
      }
      H0_.row(i) = (d / n).transpose();
      y_[i] = z[i] - n + H0_.row(i).dot(x0);
      rinv_[i] = 1.0 / variances[i];
    }
    // Eq. (11): U = -(H0^T R^-1 H0)^-1 H0^T R^-1, X~ = (H0^T R^-1 H0)^-1 H0^T R^-1 y = -U y.
    Mat<2, 2> A = Mat<2, 2>::Zero();
    for (int i = 0; i < M_; ++i) A.noalias() += rinv_[i] * H0_.row(i).transpose() * H0_.row(i);
    const double det = A.determinant();
    if (!(std::abs(det) > 1e-12 * A.trace() * A.trace())) {
      e.flags |= kFlagDegenerateGeometry;
      e.lower.setZero();
      e.upper.setZero();
      return e;
    }
    const Mat<2, 2> Ainv = A.inverse();
    for (int i = 0; i < M_; ++i) U_.col(i).noalias() = -rinv_[i] * Ainv * H0_.row(i).transpose();
    e.x_tilde.noalias() = -U_ * y_;
    // Eq. (12): L = I + H0 U, r = y - H0 X~ (= L y).
    L_.noalias() = H0_ * U_;
    L_.diagonal().array() += 1.0;
    r_ = y_;
    r_.noalias() -= H0_ * e.x_tilde;
    // Eq. (13): Sigma_v = E[v v^T] = L R L^T (v = L n, see the file comment).
    T_.noalias() = L_ * variances.asDiagonal();
    Sv_.noalias() = T_ * L_.transpose();
    // Generalised inverse Sigma_v^- = R^-1 L (file comment), symmetrised against round-off.
    Svg_.noalias() = rinv_.asDiagonal() * L_;
    nlosloc::detail::symmetrize(Svg_);

    upper_bounds(z, e);  // eq. (15), lower 0 (eq. 14)

    // Eq. (14) as min 1/2 u^T Hq u + gq^T u over u = b / s (s = sqrt(mean R): unit-scale variables):
    // (r - L b)^T Sigma_v^- (r - L b) = s^2 u^T (L^T Sigma_v^- L) u - 2 s (L^T Sigma_v^- r)^T u + const.
    const double s = std::sqrt(variances.mean());
    T_.noalias() = Svg_ * L_;
    Hq_.noalias() = L_.transpose() * T_;
    Hq_ *= 2.0 * s * s;
    nlosloc::detail::symmetrize(Hq_);
    tmp_.noalias() = Svg_ * r_;
    gq_.noalias() = L_.transpose() * tmp_;
    gq_ *= -2.0 * s;
    if (sparsity_ > 0.0) {
      // Tie-break (documented choice, see set_sparsity): + sparsity * mean(diag Hq) * sum(u), i.e. an L1
      // penalty (u >= 0) that picks, among the many minimisers, one with few and small biases.
      gq_.array() += sparsity_ * Hq_.diagonal().mean();
    }
    return solve_scaled(s, e);
  }

  /// Eqs. (12)-(15) referenced to the tracker's prediction (file comment, second form): r = innovation
  /// (M, eq. 26: z - f(X(k|k-1))), Sigma_v = D (M x M, eq. 27: F P(k|k-1) F^T + R), bounds 0 <= b <= eq. (15)
  /// from the ranges z (M). Never throws on inconsistent data (flags as in estimate(); a NaN in z or the
  /// innovation is a missing row: kFlagMissingRows, no estimate). Throws std::invalid_argument naming the
  /// argument on wrong shapes or an infinite entry of z or the innovation, and unless D is finite, symmetric
  /// (to 1e-10 of its largest |entry|) and positive definite (a covariance, eq. 27); the estimator is then
  /// unchanged, as it is when the solver throws. No heap allocation (beyond the solver).
  const BiasEstimate& estimate_from_innovation(const Eigen::Ref<const VecX>& z,
                                               const Eigen::Ref<const VecX>& innovation,
                                               const Eigen::Ref<const MatX>& D) {
    nlosloc::detail::check_measurement(z, M_, "z");
    nlosloc::detail::check_measurement(innovation, M_, "innovation");
    nlosloc::detail::ensure_shape(D, M_, M_, "D");
    nlosloc::detail::ensure_finite(D, "D");
    detail::ensure_symmetric(D, "D");
    double pivot = 0.0;
    const int row = factor_covariance(D, pivot);  // into T_, scratch: the estimator is still unchanged
    if (row >= 0)
      nlosloc::detail::throw_invalid_argument(
          "D: expected a positive definite matrix (eq. 27: F P F^T + R), got the pivot " +
          nlosloc::detail::fmt_shortest(pivot) + " at row " + std::to_string(row) +
          " of its Cholesky factorisation");
    return from_innovation_factored(z, innovation, D, true);
  }

  /// lambda of the soft threshold of estimate_from_innovation (0 = eq. 14 as written): an L1 term
  /// 2 lambda sum_i b_i / sqrt(D_ii) is added to eq. (14), so a row's bias is positive only when its
  /// innovation exceeds about lambda standard deviations (exactly so for diagonal D). Without it every
  /// positive innovation, noise included, is read as bias. >= 0 and finite.
  void set_soft_threshold(double lambda) {
    nlosloc::detail::ensure_nonnegative(lambda, "soft_threshold");
    soft_threshold_ = lambda;
  }
  double soft_threshold() const { return soft_threshold_; }

  /// Weight of the L1 tie-break added to eq. (14) (relative to the mean Hessian diagonal; 0 = the plain
  /// eq. 14, whose minimiser is not unique, leaving the pick to the solver). >= 0.
  void set_sparsity(double w) {
    nlosloc::detail::ensure_nonnegative(w, "sparsity");
    sparsity_ = w;
  }
  double sparsity() const { return sparsity_; }

  /// The last estimate.
  const BiasEstimate& last() const { return est_; }
  /// Intermediates of the last estimate (eqs. 9-14), for tests and inspection.
  const MatX& H0() const { return H0_; }             ///< eq. (10), M x 2
  const MatX& U() const { return U_; }               ///< eq. (11), 2 x M
  const MatX& L() const { return L_; }               ///< eq. (12), M x M
  const VecX& y() const { return y_; }               ///< eq. (9), M
  const VecX& r() const { return r_; }               ///< eq. (12), M
  const MatX& sigma_v() const { return Sv_; }        ///< eq. (13), M x M (eq. 27's D after the 2nd form)
  const MatX& sigma_v_ginv() const { return Svg_; }  ///< R^-1 L (snapshot) or D^-1 (2nd form)
  const MatX& qp_hessian() const { return Hq_; }     ///< QP Hessian in the scaled variables u = b / s
  const VecX& qp_gradient() const { return gq_; }    ///< QP linear term in the scaled variables

 private:
  friend class QpBiasEkf;  // estimate_from_prediction: its own D, unchecked

  /// QpBiasEkf's estimate_from_innovation: D = F P F^T + R built by the tracker (finite, symmetric to
  /// round-off), not checked; a D that is not positive definite to working precision is a flagged fallback
  /// (kFlagDegenerateGeometry, b^ = 0), not an exception, as a tracker step never throws on its own data.
  const BiasEstimate& estimate_from_prediction(const Eigen::Ref<const VecX>& z,
                                               const Eigen::Ref<const VecX>& innovation,
                                               const Eigen::Ref<const MatX>& D) {
    double pivot = 0.0;
    const bool pd = factor_covariance(D, pivot) < 0;
    return from_innovation_factored(z, innovation, D, pd);
  }

  /// Cholesky factor Lc of the symmetric part of D (D = Lc Lc^T) into T_'s lower triangle: -1, or the row
  /// whose pivot (returned in `pivot`) is not positive (D not positive definite). No allocation.
  int factor_covariance(const Eigen::Ref<const MatX>& D, double& pivot) {
    T_ = D;  // same size: no allocation
    nlosloc::detail::symmetrize(T_);
    Eigen::Index row = -1;
    return nlosloc::detail::small_cholesky_inplace(T_, &row, &pivot) ? -1 : static_cast<int>(row);
  }

  /// The second form with the factor of D in T_ (factor_covariance; pd false: it failed).
  const BiasEstimate& from_innovation_factored(const Eigen::Ref<const VecX>& z,
                                               const Eigen::Ref<const VecX>& innovation,
                                               const Eigen::Ref<const MatX>& D, bool pd) {
    save();  // same sizes: no allocation
    BiasEstimate& e = est_;
    e.flags = 0;
    e.bias.setZero();
    e.qp = QpResult{};
    if (!z.allFinite() || !innovation.allFinite()) {
      e.flags |= kFlagMissingRows;
      e.lower.setZero();
      e.upper.setZero();
      return e;
    }
    upper_bounds(z, e);  // eq. (15), lower 0 (eq. 14)
    Sv_ = D;             // Sigma_v of eq. (13) in this form (eq. 27)
    nlosloc::detail::symmetrize(Sv_);
    r_ = innovation;  // eq. (12) with X~ := X(k|k-1): r = alpha(k)
    L_.setIdentity();
    const double s = std::sqrt(std::max(Sv_.diagonal().mean(), 1e-300));  // unit-scale variables u = b / s
    if (!pd) {
      e.flags |= kFlagDegenerateGeometry;
      return e;
    }
    // Sigma_v^-1 = D^-1 through the Cholesky factor Lc of D in T_ (eq. 27 covariance, positive definite).
    Hq_.setIdentity();
    nlosloc::detail::small_forward_inplace(T_, Hq_);  // Lc^-1 (lower triangular), D = Lc Lc^T
    Svg_.noalias() = Hq_.transpose() * Hq_;           // Sigma_v^-1 = D^-1 = Lc^-T Lc^-1
    // Eq. (14) with L = I: (r - b)^T D^-1 (r - b) = s^2 u^T D^-1 u - 2 s (D^-1 r)^T u + const.
    Hq_ = (2.0 * s * s) * Svg_;
    nlosloc::detail::symmetrize(Hq_);
    gq_.noalias() = Svg_ * innovation;
    gq_ *= -2.0 * s;
    // Soft threshold (set_soft_threshold; not in Ke & Wu): + 2 lambda sum_i b_i / sqrt(D_ii), i.e. eq. (14)
    // plus an L1 term that, for diagonal D, gives b_i = clip(r_i - lambda sqrt(D_ii), 0, b_i^U).
    if (soft_threshold_ > 0.0)
      for (int i = 0; i < M_; ++i) gq_[i] += 2.0 * soft_threshold_ * s / std::sqrt(Sv_(i, i));
    return solve_scaled(s, e);
  }

  /// What a call may change (the last estimate and the exposed intermediates), saved at its start and
  /// restored when the solver throws: a rejected call leaves the estimator as it was. Same sizes every
  /// time, so saving copies without allocating.
  struct Saved {
    MatX H0, U, L, Sv, Svg, Hq;
    VecX y, r, gq;
    BiasEstimate est;
  };
  void save() {
    saved_.H0 = H0_;
    saved_.U = U_;
    saved_.L = L_;
    saved_.Sv = Sv_;
    saved_.Svg = Svg_;
    saved_.Hq = Hq_;
    saved_.y = y_;
    saved_.r = r_;
    saved_.gq = gq_;
    saved_.est = est_;
  }
  // Copies back (same sizes: no allocation) rather than swapping buffers, so arrays that Python holds on
  // the intermediates (views of these members) show the restored values.
  void restore() {
    H0_ = saved_.H0;
    U_ = saved_.U;
    L_ = saved_.L;
    Sv_ = saved_.Sv;
    Svg_ = saved_.Svg;
    Hq_ = saved_.Hq;
    y_ = saved_.y;
    r_ = saved_.r;
    gq_ = saved_.gq;
    est_ = saved_.est;
  }

  /// Solves the QP in u = b / s (Hq_, gq_ set by the caller) within the eq. (15) box of e and writes
  /// b = s u, clamped to the box, into e; on solver failure b = 0 and kFlagQpFailed.
  BiasEstimate& solve_scaled(double s, BiasEstimate& e) {
    lq_ = e.lower / s;
    uq_ = e.upper / s;
    try {
      e.qp = solver_->solve(Hq_, gq_, lq_, uq_);
    } catch (...) {
      restore();  // a solver that throws (one written in Python, say) leaves the estimator as it was
      throw;
    }
    if (!e.qp.ok() || !solver_->x().allFinite()) {
      e.flags |= kFlagQpFailed;
      e.bias.setZero();
      return e;
    }
    e.bias = s * solver_->x();
    e.bias = e.bias.cwiseMax(e.lower).cwiseMin(e.upper);
    return e;
  }

  // Eq. (15): b_i^U = min_j (z_i + z_j - l_ij); eq. (14): b_i^L = 0. Documented clamp when b^U < b^L.
  template <class DZ>
  void upper_bounds(const Eigen::MatrixBase<DZ>& z, BiasEstimate& e) const {
    for (int i = 0; i < M_; ++i) {
      double u = std::numeric_limits<double>::infinity();
      for (int j = 0; j < M_; ++j)
        if (j != i) u = std::min(u, z[i] + z[j] - l_(i, j));
      e.lower[i] = 0.0;
      if (u < 0.0) {
        u = 0.0;
        e.flags |= kFlagBoundsClamped;
      }
      e.upper[i] = u;
    }
  }

  MatX anchors_;
  int M_;
  BoxQpHandle solver_;
  double sparsity_ = 0.0;
  double soft_threshold_ = 0.0;
  MatX l_;  ///< l_ij, anchor distances (eq. 15)
  MatX H0_, U_, L_, Sv_, Svg_, T_, Hq_;
  VecX gq_, y_, r_, rinv_, lq_, uq_, tmp_;
  BiasEstimate est_;
  Saved saved_;  ///< the state before the current call, restored when the solver throws
};

}  // namespace nlosloc::mitigation
