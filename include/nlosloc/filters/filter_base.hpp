#pragma once
/// \file filter_base.hpp
/// State handling shared by KF, EKF and UKF: the linear prediction (all motion models are linear),
/// validated set/get of the belief, and step() = predict + update with the state restored when the
/// update is rejected.
#include <string>

#include "nlosloc/filters/common.hpp"
#include "nlosloc/models/motion.hpp"

namespace nlosloc {

/// CRTP base; Derived provides `StepResult update(const Eigen::Ref<const VecX>& y, const VecXi* sight)`.
template <class Derived, class Motion>
class FilterBase {
 public:
  static constexpr int kDim = Motion::kDim;
  using State = Vec<kDim>;
  using Cov = Mat<kDim, kDim>;

  /// Prediction x = F x, P = F P F^T + Q (Huerta eqs. 4, 6-7; Ke and Wu eq. 16; Grisales eq. 14), and
  /// time advances by dt. Exact for the linear models, so the UKF needs no sigma points here.
  void predict() {
    const State x = motion_.F() * x_;
    Cov P = motion_.F() * P_ * motion_.F().transpose() + motion_.Q();
    detail::symmetrize(P);
    x_ = x;
    P_ = P;
    t_ += motion_.dt();
  }

  /// predict() then update(y, sight); if the update throws, the belief and time are restored.
  StepResult step(const Eigen::Ref<const VecX>& y, const VecXi* sight = nullptr) {
    const State x0 = x_;
    const Cov P0 = P_;
    const double t0 = t_;
    derived().precheck(y, sight);  // reject bad input before touching the state
    predict();
    try {
      return derived().update_unchecked(y, sight);
    } catch (...) {
      x_ = x0;
      P_ = P0;
      t_ = t0;
      throw;
    }
  }
  StepResult step(const Eigen::Ref<const VecX>& y, const VecXi& sight) { return step(y, &sight); }

  const State& mean() const { return x_; }
  const Cov& cov() const { return P_; }
  Gaussian<kDim> belief() const { return {x_, P_}; }
  double time() const { return t_; }
  const Motion& motion() const { return motion_; }

  /// Replaces the belief (validated: finite mean, symmetric positive definite covariance) and time.
  void set_belief(const Gaussian<kDim>& b, double t) {
    b.validate("belief");
    NLOSLOC_ENSURE(std::isfinite(t), "t: expected a finite time (s)");
    x_ = b.mean;
    P_ = b.cov;
    t_ = t;
  }
  void set_belief(const Gaussian<kDim>& b) { set_belief(b, t_); }

 protected:
  FilterBase(const Motion& motion, const Gaussian<kDim>& initial, double t0) : motion_(motion) {
    initial.validate("initial");
    NLOSLOC_ENSURE(std::isfinite(t0), "t0: expected a finite time (s)");
    x_ = initial.mean;
    P_ = initial.cov;
    t_ = t0;
  }
  /// Raises NumericalError for a failed factorisation; the caller has not modified the belief yet.
  [[noreturn]] static void fail(const char* what) {
    detail::throw_numerical_error(std::string(what) +
                                  ": covariance not positive definite even with the Cholesky fallback");
  }
  Derived& derived() { return static_cast<Derived&>(*this); }

  Motion motion_;
  State x_;
  Cov P_;
  double t_ = 0.0;
};

}  // namespace nlosloc
