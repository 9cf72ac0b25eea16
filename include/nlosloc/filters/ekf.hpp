#pragma once
/// \file ekf.hpp
/// Extended Kalman filter over a measurement stack: y = g(x) + n(s), linearised at the prediction.
#include "nlosloc/filters/filter_base.hpp"
#include "nlosloc/models/measurement.hpp"

namespace nlosloc {

/// EKF whose measurement noise moments follow the sight condition of each row's anchor
/// (an EKF-LOS is this filter with all anchors in condition 0).
template <class Motion, class Meas = MeasurementStack>
class Ekf : public FilterBase<Ekf<Motion, Meas>, Motion> {
  using Base = FilterBase<Ekf<Motion, Meas>, Motion>;
  friend Base;

 public:
  using Base::kDim;

  Ekf(const Motion& motion, const Meas& meas, const Gaussian<kDim>& initial, double t0 = 0.0)
      : Base(motion, initial, t0), meas_(meas) {
    detail::check_layout<kDim>(meas);
    meas.check_ready();
    meas.check_finite_moments("Ekf");
    const int m = meas.rows();
    tail_.resize(m);
    H_.setZero(m, kDim);
    nmean_.setZero(m);
    R_.setZero(m, m);
    y_.setZero(m);
    los_.setZero(meas.num_anchors());
  }

  const Meas& measurements() const { return meas_; }

  /// EKF update (Ke and Wu eqs. 17-21 with the noise of the current sight): NaN rows are skipped.
  StepResult update(const Eigen::Ref<const VecX>& y, const VecXi* sight = nullptr) {
    precheck(y, sight);
    return update_unchecked(y, sight);
  }
  StepResult update(const Eigen::Ref<const VecX>& y, const VecXi& sight) { return update(y, &sight); }

 private:
  StepResult update_unchecked(const Eigen::Ref<const VecX>& y, const VecXi* sight) {
    const VecXi& s = sight ? *sight : los_;
    y_ = y;
    StepResult res;
    auto& t = tail_;
    meas_.predict(this->x_, this->t_, t.zhat);
    meas_.noise_moments(this->x_, s, nmean_, R_);
    t.zhat += nmean_;
    meas_.jacobian(this->x_, this->t_, H_);
    t.Pxz.noalias() = this->P_.lazyProduct(H_.transpose());  // P H^T
    t.S.noalias() = H_.lazyProduct(t.Pxz);                   // H P H^T + R
    t.S += R_;
    if (!t.apply(
            y_, [this](VecX& r) { meas_.wrap_residual(r); }, this->x_, this->P_, res))
      Base::fail("Ekf.update: S");
    return res;
  }

 private:
  void precheck(const Eigen::Ref<const VecX>& y, const VecXi* sight) const {
    detail::check_measurement(y, meas_.rows());
    if (sight) meas_.check_sight(*sight);
  }
  Meas meas_;
  Eigen::Matrix<double, Eigen::Dynamic, kDim> H_;
  VecX nmean_, y_;
  MatX R_;
  VecXi los_;
  detail::UpdateTail<kDim> tail_;
};

}  // namespace nlosloc
