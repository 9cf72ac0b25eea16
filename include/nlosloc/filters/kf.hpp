#pragma once
/// \file kf.hpp
/// Linear Kalman filter y = H x + n, n ~ N(0, R), over a linear motion model.
#include "nlosloc/filters/filter_base.hpp"

namespace nlosloc {

/// Kalman filter with a fixed observation matrix H (m x n) and noise covariance R (m x m).
template <class Motion>
class Kf : public FilterBase<Kf<Motion>, Motion> {
  using Base = FilterBase<Kf<Motion>, Motion>;
  friend Base;

 public:
  using Base::kDim;

  /// H: m x kDim, finite; R: m x m symmetric positive definite; initial: validated belief.
  Kf(const Motion& motion, const MatX& H, const MatX& R, const Gaussian<kDim>& initial, double t0 = 0.0)
      : Base(motion, initial, t0), H_(H), R_(R) {
    detail::ensure_shape(H, -1, kDim, "H");
    NLOSLOC_ENSURE(H.rows() > 0, "H: expected at least one row");
    detail::ensure_finite(H, "H");
    detail::ensure_shape(R, H.rows(), H.rows(), "R");
    NLOSLOC_ENSURE(is_spd(R), "R: expected a symmetric positive definite matrix");
    tail_.resize(static_cast<int>(H.rows()));
    y_.setZero(H.rows());
  }

  int rows() const { return static_cast<int>(H_.rows()); }
  const MatX& H() const { return H_; }
  const MatX& R() const { return R_; }

  /// Kalman update with y (m; NaN rows missing). `sight` is not used by the KF and must be null.
  StepResult update(const Eigen::Ref<const VecX>& y, const VecXi* sight = nullptr) {
    precheck(y, sight);
    return update_unchecked(y, sight);
  }

 private:
  StepResult update_unchecked(const Eigen::Ref<const VecX>& y, const VecXi* /*sight*/) {
    y_ = y;
    StepResult res;
    auto& t = tail_;
    t.zhat.noalias() = H_.lazyProduct(this->x_);             // z = H x
    t.Pxz.noalias() = this->P_.lazyProduct(H_.transpose());  // P H^T
    t.S.noalias() = H_.lazyProduct(t.Pxz);                   // H P H^T
    t.S += R_;
    if (!t.apply(
            y_, [](VecX&) {}, this->x_, this->P_, res))
      Base::fail("Kf.update: S");
    return res;
  }

 private:
  void precheck(const Eigen::Ref<const VecX>& y, const VecXi* sight) const {
    detail::check_measurement(y, H_.rows());
    NLOSLOC_ENSURE(sight == nullptr, "sight: the KF has no sight-dependent noise; pass none");
  }
  MatX H_, R_;
  VecX y_;
  detail::UpdateTail<kDim> tail_;
};

}  // namespace nlosloc
