#pragma once
/// \file ukf_kernel.hpp
/// The per-particle UKF of the RBPF bank (Huerta Table III) as a workspace that updates a bare (mean,
/// covariance) pair, so a bank of thousands of particles needs no filter objects. Split in two stages:
/// prepare() predicts once per parent, finish() updates one offspring.
///  - NoiseForm::kAdditive (default): the sigma points of a parent and their images g(X) do not depend on
///    the situation vector, so prepare() evaluates them once; finish() adds the situation's noise moments
///    and applies the Kalman update (one small Cholesky per offspring). Math of nlosloc::Ukf::update.
///  - NoiseForm::kAugmented: Table III as written, the noise sigma set N_s inside the points (III.1). The
///    images depend on s (quantile maps), so finish() evaluates all 2(n + q) + 1 points per offspring:
///    dearer. A skewed NLOS noise (Rayleigh median != mean) bends the points as in the paper, but its
///    moments are an unscented approximation (H1's Rayleigh of variance 2000 at the default alpha = 1e-3:
///    mean 85.52 for 85.56, variance +10%), where the additive form uses the exact noise mean and
///    variance. Math of UkfAugmented::update.
#include "nlosloc/core/sigma_points.hpp"
#include "nlosloc/filters/common.hpp"
#include "nlosloc/filters/ukf.hpp"
#include "nlosloc/models/measurement.hpp"

namespace nlosloc::rbpf {

/// Workspace for one thread: predict + unscented update of (x, P) given a situation vector.
template <class Motion, class Meas = MeasurementStack>
class UkfKernel {
 public:
  static constexpr int N = Motion::kDim;
  static constexpr int K = 2 * N + 1;

  /// Buffers sized for `meas`; later calls must pass a stack with the same rows (it may be another copy:
  /// the kernel keeps no reference between prepare() calls, so the owning filter stays movable).
  UkfKernel(const Meas& meas, const SigmaScheme& scheme, NoiseForm form = NoiseForm::kAdditive)
      : meas_(&meas), form_(form), w_(scheme.weights(sigma_dim(meas, form))) {
    const int m = meas.rows();
    tail_.resize(m);
    if (form == NoiseForm::kAugmented) {
      aug_.resize(m, meas.noise_dim(), scheme);
      return;
    }
    mom_.resize(m);
    S0_.setZero(m, m);
    Pxz0_.setZero(N, m);
    zhat0_.setZero(m);
    nmean_.setZero(m);
    R_.setZero(m, m);
  }

  /// Dimension of the unscented transform: n, or n + q with the noise inputs (Huerta eq. 49, L_a = n + q;
  /// the state points then spread wider than in the additive form).
  static int sigma_dim(const Meas& meas, NoiseForm form) {
    return form == NoiseForm::kAugmented ? N + meas.noise_dim() : N;
  }

  /// Stage 1 (Table III, first three items): x_p = F x, P_p = F P F^T + Q (exact, linear motion) and the
  /// factor of P_p; additive form: also the sigma points of (x_p, P_p) (eq. 49) and their predicted
  /// observations g(X) at time t. Returns the Cholesky status; kFailed leaves the kernel unusable until
  /// the next prepare().
  CholeskyStatus prepare(const Motion& motion, const Meas& meas, const Vec<N>& x, const Mat<N, N>& P,
                         double t) {
    meas_ = &meas;
    xp_.noalias() = motion.F() * x;
    Pp_.noalias() = motion.F() * P * motion.F().transpose();
    Pp_ += motion.Q();
    nlosloc::detail::symmetrize(Pp_);
    t_ = t;
    status_ = nlosloc::detail::factor_state_cov(Pp_, L_, &jitter_);
    if (status_ == CholeskyStatus::kFailed || form_ == NoiseForm::kAugmented) return status_;
    mom_.compute(*meas_, xp_, L_, w_, t, zhat0_, S0_, Pxz0_);  // Huerta eqs. (49)-(51), no noise
    return status_;
  }

  /// Stage 2: adds the noise moments of situation `s` (Table III.1 with additive noise), applies the Kalman
  /// update with y and writes the posterior into (x_out, P_out). res.log_likelihood is the predictive
  /// log N(y; y_hat, S) used by eq. (25). Returns false when S cannot be factorised.
  bool finish(const VecXi& s, const VecX& y, Vec<N>& x_out, Mat<N, N>& P_out, StepResult& res) {
    res = StepResult{};
    res.status = status_;
    res.jitter = jitter_;
    auto& t = tail_;
    if (form_ == NoiseForm::kAugmented) {
      aug_.compute(*meas_, xp_, L_, w_, t_, s, t.zhat, t.S, t.Pxz, &y);  // Table III.1, eqs. (49)-(51)
    } else {
      meas_->noise_moments(xp_, s, nmean_, R_);
      t.S = S0_;
      t.S += R_;
      t.Pxz = Pxz0_;
      t.zhat = zhat0_;
      t.zhat += nmean_;
    }
    x_out = xp_;
    P_out = Pp_;
    return t.apply(
        y, [this](VecX& r) { meas_->wrap_residual(r); }, x_out, P_out, res);
  }

  /// Predicted mean F x of the last prepare().
  const Vec<N>& predicted_mean() const { return xp_; }
  const Mat<N, N>& predicted_cov() const { return Pp_; }

 private:
  const Meas* meas_;
  NoiseForm form_;
  SigmaWeights w_;
  double t_ = 0.0;
  Vec<N> xp_;
  Mat<N, N> Pp_, L_;
  nlosloc::detail::SigmaMoments<N> mom_;
  nlosloc::detail::AugmentedMoments<N> aug_;
  MatX S0_, R_;
  Eigen::Matrix<double, N, Eigen::Dynamic> Pxz0_;
  VecX zhat0_, nmean_;
  nlosloc::detail::UpdateTail<N> tail_;
  CholeskyStatus status_ = CholeskyStatus::kOk;
  double jitter_ = 0.0;
};

}  // namespace nlosloc::rbpf
