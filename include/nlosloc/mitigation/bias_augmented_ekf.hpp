#pragma once
/// \file bias_augmented_ekf.hpp
/// The "iterated NLOS EKF" baseline of Ke & Wu 2011 (their ref. [15]: Najar and Vidal, "Kalman tracking for
/// mobile location in NLOS situations", PIMRC 2003), as Ke & Wu's Sec. 1 describes it: "a modified Kalman
/// tracker which increases the dimension of the state vector by adding the NLOS bias as additional
/// parameters to be estimated". The original paper is not in papers/; the form implemented is:
///   state      X = [x, y, vx, vy, b_1 .. b_M]                      (one NLOS bias per anchor)
///   motion     [x y vx vy] by Ke & Wu eq. (16); b_k = b_{k-1} + w_b, w_b ~ N(0, sigma_w^2 I)  (random walk)
///   measure    z_i = ||p - a_i|| + b_i + n_i                       (Ke & Wu eq. 1 with b_i in the state)
///   update     one EKF update per step by default (J = 1): Najar and Vidal's abstract describes "the
///              Kalman filter ... includes the time measurement bias for each base station as additional
///              parameters", with no iterated update; Ke & Wu's "iterated" is read as the bias being tracked
///              recursively. On K1 (issue #4) J = 2-3 made every NLOS case worse (1 NLOS node, 67%: 108 m
///              with J = 1, 297 m with J = 2). Optional iterated EKF (Bell and Cathey 1993): for j = 0..J-1
///                H_j = dh/dX at X_j, K_j = P H_j^T (H_j P H_j^T + R)^-1,
///                X_{j+1} = X^- + K_j [z - h(X_j) - H_j (X^- - X_j)],   X_0 = X^-
///              then P = P^- - K S K^T with the last linearisation; biases projected onto b >= 0 (b_i >= 0,
///              Ke & Wu Sec. 2) after the update.
#include <algorithm>
#include <cmath>
#include <string>

#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/filters/common.hpp"
#include "nlosloc/mitigation/bias_estimation.hpp"
#include "nlosloc/models/motion.hpp"

namespace nlosloc::mitigation {

/// Options of BiasAugmentedEkf.
struct BiasAugmentedEkfOptions {
  RangeNoise noise{};             ///< R: std_i = sigma0 + relative * d_i at the current iterate
  double bias_prior_mean = 0.0;   ///< initial mean of every b_i (m), >= 0
  double bias_prior_std = 500.0;  ///< initial std of every b_i (m), > 0
  double bias_walk_std = 1.0;     ///< random-walk std of b_i per step (m), >= 0
  int iterations = 1;             ///< iterated-EKF iterations J >= 1 (1 = plain EKF over the augmented state)
  bool nonnegative = true;        ///< project the bias means onto b >= 0 after each update

  void validate() const {
    noise.validate("options.noise");
    nlosloc::detail::ensure_nonnegative(bias_prior_mean, "options.bias_prior_mean");
    nlosloc::detail::ensure_positive(bias_prior_std, "options.bias_prior_std");
    nlosloc::detail::ensure_nonnegative(bias_walk_std, "options.bias_walk_std");
    NLOSLOC_ENSURE(iterations >= 1 && iterations <= 100,
                   "options.iterations: expected 1..100, got " + std::to_string(iterations));
  }
};

/// Bias-augmented ("iterated NLOS") EKF, 2-D, M >= 1 TOA anchors; state size 4 + M. Buffers are sized at
/// construction; a step does not allocate. It does not use the shared detail::UpdateTail: that tail is
/// fixed-size in the state (N known at compile time) and forms the innovation from y - z_hat, while this
/// filter's state size depends on the anchor count and the iterated form's innovation is
/// z - h(X_j) - H_j (X^- - X_j); a failed factorisation keeps the predicted belief (no jitter fallback).
class BiasAugmentedEkf {
 public:
  /// motion: eq. (16); anchors M x 2; initial: belief of [x, y, vx, vy] (the biases start from the
  /// options' prior, independent of the kinematics); t0 start time (s).
  BiasAugmentedEkf(const ConstantVelocity2& motion, const MatX& anchors, const Gaussian<4>& initial,
                   const BiasAugmentedEkfOptions& options = {}, double t0 = 0.0)
      : motion_(motion), anchors_(anchors), opt_(options) {
    nlosloc::detail::ensure_shape(anchors, -1, 2, "anchors");
    NLOSLOC_ENSURE(anchors.rows() >= 1, "anchors: expected at least one anchor (row)");
    nlosloc::detail::ensure_finite(anchors, "anchors");
    opt_.validate();
    M_ = static_cast<int>(anchors.rows());
    n_ = 4 + M_;
    x_.setZero(n_);
    P_.setZero(n_, n_);
    Phi_.setIdentity(n_, n_);
    Phi_.topLeftCorner<4, 4>() = motion_.F();
    Q_.setZero(n_, n_);
    Q_.topLeftCorner<4, 4>() = motion_.Q();
    Q_.bottomRightCorner(M_, M_).diagonal().setConstant(opt_.bias_walk_std * opt_.bias_walk_std);
    T_.setZero(n_, n_);
    H_.setZero(M_, n_);
    HP_.setZero(M_, n_);
    Kt_.setZero(M_, n_);
    S_.setZero(M_, M_);
    Lc_.setZero(M_, M_);
    innov_.setZero(M_);
    w_.setZero(M_);
    xpred_.setZero(n_);
    dx_.setZero(n_);
    set_belief(initial, t0);
  }

  int num_anchors() const { return M_; }
  int state_dim() const { return n_; }
  const MatX& anchors() const { return anchors_; }
  const BiasAugmentedEkfOptions& options() const { return opt_; }
  const ConstantVelocity2& motion() const { return motion_; }
  /// Full state [x, y, vx, vy, b_1 .. b_M] and its covariance.
  const VecX& mean() const { return x_; }
  const MatX& cov() const { return P_; }
  /// The kinematic part [x, y, vx, vy].
  Vec<4> kinematic_mean() const { return x_.head<4>(); }
  /// The bias estimates b_1 .. b_M (m).
  VecX bias() const { return x_.tail(M_); }
  double time() const { return t_; }

  /// Sets the kinematic belief (validated) and time, and resets the biases to the options' prior.
  void set_belief(const Gaussian<4>& b, double t) {
    b.validate("belief");
    NLOSLOC_ENSURE(std::isfinite(t), "t: expected a finite time (s)");
    x_.setZero();
    P_.setZero();
    x_.head<4>() = b.mean;
    P_.topLeftCorner<4, 4>() = b.cov;
    x_.tail(M_).setConstant(opt_.bias_prior_mean);
    P_.bottomRightCorner(M_, M_).diagonal().setConstant(opt_.bias_prior_std * opt_.bias_prior_std);
    t_ = t;
  }
  /// set_belief(b, time()): keeps the time, as FilterBase::set_belief(b) does.
  void set_belief(const Gaussian<4>& b) { set_belief(b, t_); }

  /// Replaces the whole belief, biases included: mean [x, y, vx, vy, b_1 .. b_M] and its covariance
  /// (4 + M; finite mean, symmetric positive definite covariance), and the time; std::invalid_argument
  /// naming the argument otherwise (the filter is then unchanged). With mean(), cov() and time(), the whole
  /// state: a filter set from another's steps on exactly as that one (the Python bindings pickle so).
  void set_augmented_belief(const Gaussian<Eigen::Dynamic>& b, double t) {
    nlosloc::detail::ensure_shape(b.mean, n_, 1, "belief.mean");
    b.validate("belief");
    NLOSLOC_ENSURE(std::isfinite(t), "t: expected a finite time (s)");
    x_ = b.mean;
    P_ = b.cov;
    t_ = t;
  }

  /// Prediction: eq. (16) on the kinematics, random walk on the biases.
  void predict() {
    xpred_.noalias() = Phi_ * x_;
    x_ = xpred_;
    T_.noalias() = Phi_ * P_;
    P_.noalias() = T_ * Phi_.transpose();
    P_ += Q_;
    nlosloc::detail::symmetrize(P_);
    t_ += motion_.dt();
  }

  /// Iterated EKF update with ranges z (M; NaN rows skipped). If S cannot be factorised or the result is not
  /// finite, the predicted belief is kept and StepResult::status is kFailed (never NaN in the state).
  StepResult update(const Eigen::Ref<const VecX>& z) {
    nlosloc::detail::check_measurement(z, M_, "z");
    return update_unchecked(z);
  }

  /// predict() then update(z); bad input is rejected before predicting.
  StepResult step(const Eigen::Ref<const VecX>& z) {
    nlosloc::detail::check_measurement(z, M_, "z");
    predict();
    return update_unchecked(z);
  }

 private:
  StepResult update_unchecked(const Eigen::Ref<const VecX>& z) {
    StepResult res;
    xpred_ = x_;  // X^-
    dx_ = x_;     // X_j, the current linearisation point
    int used = 0;
    for (int j = 0; j < opt_.iterations; ++j) {
      used = 0;
      H_.setZero();
      for (int i = 0; i < M_; ++i) {
        const Vec<2> d = dx_.head<2>() - anchors_.row(i).transpose();
        const double n = d.norm();
        if (n > 1e-12) {
          H_(i, 0) = d[0] / n;
          H_(i, 1) = d[1] / n;
        }
        H_(i, 4 + i) = 1.0;
        if (std::isnan(z[i])) {
          innov_[i] = 0.0;
          continue;
        }
        ++used;
        // z - h(X_j) - H_j (X^- - X_j)
        innov_[i] = z[i] - (n + dx_[4 + i]) - H_.row(i).dot(xpred_ - dx_);
      }
      HP_.noalias() = H_ * P_;
      S_.noalias() = HP_ * H_.transpose();
      for (int i = 0; i < M_; ++i) {
        const Vec<2> d = dx_.head<2>() - anchors_.row(i).transpose();
        const double sd = opt_.noise.std_at(d.norm());
        S_(i, i) += sd * sd;
        if (std::isnan(z[i])) {  // missing row: neutral (unit variance, no cross covariance)
          S_.row(i).setZero();
          S_.col(i).setZero();
          S_(i, i) = 1.0;
          HP_.row(i).setZero();
        }
      }
      res.rows_used = used;
      if (used == 0) return res;
      nlosloc::detail::symmetrize(S_);
      Lc_ = S_;
      if (!S_.allFinite() || !nlosloc::detail::small_cholesky_inplace(Lc_)) {
        x_ = xpred_;
        res.status = CholeskyStatus::kFailed;
        return res;
      }
      Kt_ = HP_;
      nlosloc::detail::small_forward_inplace(Lc_, Kt_);  // L^-1 H P
      w_ = innov_;
      nlosloc::detail::small_forward_inplace(Lc_, w_);  // L^-1 innovation
      dx_ = xpred_;
      dx_.noalias() += Kt_.transpose() * w_;  // X_{j+1} = X^- + K [ ... ]
    }
    if (!dx_.allFinite()) {
      x_ = xpred_;
      res.status = CholeskyStatus::kFailed;
      return res;
    }
    T_.noalias() = Kt_.transpose() * Kt_;  // K S K^T
    P_ -= T_;
    nlosloc::detail::symmetrize(P_);
    x_ = dx_;
    if (opt_.nonnegative)
      for (int i = 0; i < M_; ++i) x_[4 + i] = std::max(x_[4 + i], 0.0);  // b_i >= 0 (Ke & Wu Sec. 2)
    double log_det = 0.0;
    for (int i = 0; i < M_; ++i) log_det += std::log(Lc_(i, i));
    res.log_likelihood =
        -0.5 * (static_cast<double>(used) * std::log(2.0 * kPi) + 2.0 * log_det + w_.squaredNorm());
    return res;
  }

  ConstantVelocity2 motion_;
  MatX anchors_;
  BiasAugmentedEkfOptions opt_;
  int M_ = 0, n_ = 0;
  VecX x_;
  MatX P_, Phi_, Q_, T_;
  double t_ = 0.0;
  MatX H_, HP_, Kt_, S_, Lc_;
  VecX innov_, w_, xpred_, dx_;
};

}  // namespace nlosloc::mitigation
