#pragma once
/// \file iukf.hpp
/// Improved UKF of Huerta et al. 2009 (Sec. V-C, Table VI) for N_z sight conditions (Grisales eqs. 36-37):
/// the sight condition of every anchor is estimated from the quality statistics alone by the per-anchor
/// forward filter (eqs. 34-38), and the UKF update uses one sigma set per condition, weighted per
/// measurement row by the probabilities of that row's anchor.
///
/// Form used (the paper's Table VI leaves the weighting of the doubled set loose): the sigma points of the
/// state are shared; set j adds the noise of condition j. Row i's predicted mean, and the covariance between
/// rows of the same anchor, are the mixture over j with weights gamma_{j, b(i)} (eq. 40): mean
/// sum_j gamma_j (g + mu_j), covariance sum_j gamma_j (Cov(g) + R_j + (mu_j - mu)(mu_j - mu)^T). Rows of
/// different anchors are independent given the state (eq. 34). With certain probabilities (one-hot gamma)
/// this is exactly the UKF (filters/ukf.hpp) with that situation vector. TDOA rows use the probabilities of
/// their first anchor for both ends (an approximation; every other row type is exact).
/// The probabilities are the forward filter's posterior after o_t (Grisales eq. 36); Table VI writes the
/// predicted gamma_{t|t-1}, which ignores the current statistic.
#include <string>
#include <utility>

#include "nlosloc/filters/ukf.hpp"
#include "nlosloc/situation/forward.hpp"

namespace nlosloc {

/// IUKF: UKF with a per-anchor HMM on the sight conditions driven by quality statistics.
template <class Motion, class Meas = MeasurementStack>
class Iukf : public FilterBase<Iukf<Motion, Meas>, Motion> {
  using Base = FilterBase<Iukf<Motion, Meas>, Motion>;
  friend Base;

 public:
  using Base::kDim;
  static constexpr int kPoints = 2 * kDim + 1;

  Iukf(const Motion& motion, const Meas& meas, const Gaussian<kDim>& initial,
       situation::ForwardFilter forward, const SigmaScheme& scheme = SigmaScheme::scaled(), double t0 = 0.0)
      : Base(motion, initial, t0),
        meas_(meas),
        fwd_(std::move(forward)),
        scheme_(scheme),
        w_(scheme.weights(kDim)) {
    detail::check_layout<kDim>(meas);
    meas.check_ready();
    meas.check_finite_moments("Iukf");
    NLOSLOC_ENSURE(fwd_.num_anchors() == meas.num_anchors(),
                   "forward: expected " + std::to_string(meas.num_anchors()) + " anchors");
    NLOSLOC_ENSURE(fwd_.num_conditions() == meas.num_conditions(),
                   "forward: expected " + std::to_string(meas.num_conditions()) + " conditions");
    NLOSLOC_ENSURE(!fwd_.process().speed_dependent() || meas.layout().velocity >= 0,
                   "forward: a speed-dependent chain needs a velocity in the state layout");
    const int m = meas.rows(), nz = meas.num_conditions();
    tail_.resize(m);
    mom_.resize(m);
    Rn_.setZero(m, m);
    Rj_.setZero(m, m);
    mu_.setZero(m, nz);
    var_.setZero(m, m);
    nmean_.setZero(m);
    y_.setZero(m);
    sj_.setZero(meas.num_anchors());
    speeds_.setZero(meas.num_anchors());
    Pi_.setZero(m, nz);
    onehot_.setZero(meas.num_anchors(), nz);
    fwd_.save(fsave_);  // sizes the snapshot buffers
  }

  /// predict(); forward filter step with o (size B, NaN = missing; transversal speeds from the predicted
  /// mean); update with its probabilities. The state is restored if the update throws.
  StepResult step_quality(const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o) {
    detail::check_measurement(y, meas_.rows());
    situation::check_statistics(o, meas_.num_anchors());
    const auto x0 = this->x_;
    const auto P0 = this->P_;
    const double t0 = this->t_;
    fwd_.save(fsave_);  // preallocated: no copy of the chains
    this->predict();
    try {
      if (fwd_.process().speed_dependent()) {  // eq. (10) at the predicted mean (the paper does not say)
        const auto& L = meas_.layout();
        situation::detail::state_transversal_speeds(this->x_.segment(L.position, L.space_dim),
                                                    this->x_.segment(L.velocity, L.space_dim),
                                                    meas_.anchors(), speeds_, "Iukf.step");
      }
      fwd_.step(o, speeds_);  // eqs. (36)-(38)
      return update_mixture(y, fwd_.probabilities());
    } catch (...) {
      this->x_ = x0;
      this->P_ = P0;
      this->t_ = t0;
      fwd_.restore(fsave_);
      throw;
    }
  }

  /// Update with explicit per-anchor condition probabilities gamma (B x N_z, rows summing to one).
  StepResult update_with_probabilities(const Eigen::Ref<const VecX>& y, const MatX& gamma) {
    detail::check_measurement(y, meas_.rows());
    situation::check_probabilities(gamma, meas_.num_anchors(), meas_.num_conditions(), "gamma");
    return update_mixture(y, gamma);
  }

  /// The forward filter (probabilities of the last step: forward().probabilities()).
  const situation::ForwardFilter& forward() const { return fwd_; }
  situation::ForwardFilter& forward() { return fwd_; }
  /// Most probable condition per anchor.
  VecXi sight_estimate() const { return fwd_.argmax(); }
  const Meas& measurements() const { return meas_; }
  const SigmaScheme& scheme() const { return scheme_; }
  /// Throws the std::invalid_argument step_quality(y, o) would throw for these inputs, and changes nothing.
  void check_inputs(const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o) const {
    situation::check_step_inputs(meas_, fwd_.quality(), y, o);
  }

 private:
  void precheck(const Eigen::Ref<const VecX>& y, const VecXi* sight) const {
    detail::check_measurement(y, meas_.rows());
    if (sight) meas_.check_sight(*sight);
  }
  /// FilterBase::step(y, sight): a known situation vector (one-hot probabilities) = the plain UKF.
  StepResult update_unchecked(const Eigen::Ref<const VecX>& y, const VecXi* sight) {
    onehot_.setZero();
    for (int b = 0; b < meas_.num_anchors(); ++b) onehot_(b, sight ? (*sight)(b) : 0) = 1.0;
    return update_mixture(y, onehot_);
  }

  StepResult update_mixture(const Eigen::Ref<const VecX>& y, const MatX& gamma) {
    y_ = y;
    const int m = meas_.rows(), nz = meas_.num_conditions();
    StepResult res;
    Mat<kDim, kDim> L;
    res.status = detail::factor_state_cov(this->P_, L, &res.jitter);
    if (res.status == CholeskyStatus::kFailed) Base::fail("Iukf.update: P");
    auto& t = tail_;
    mom_.compute(meas_, this->x_, L, w_, this->t_, t.zhat, t.S, t.Pxz);  // eqs. (49)-(51), (VI.3)
    // Row weights: gamma of the row's anchor (rows without an anchor are always condition 0).
    for (int i = 0; i < m; ++i) {
      const int b = meas_.row(i).anchor;
      for (int j = 0; j < nz; ++j) Pi_(i, j) = b < 0 ? (j == 0 ? 1.0 : 0.0) : gamma(b, j);
    }
    // One noise set per condition j (VI.1 / Grisales eq. 37), mixed row by row (eq. 40).
    nmean_.setZero();
    var_.setZero();
    for (int j = 0; j < nz; ++j) {
      sj_.setConstant(j);
      auto mj = mu_.col(j);
      meas_.noise_moments(this->x_, sj_, mj, Rj_);
      for (int i = 0; i < m; ++i) nmean_(i) += Pi_(i, j) * mu_(i, j);
      for (int i = 0; i < m; ++i)
        for (int k = 0; k < m; ++k)
          if (same_anchor(i, k)) var_(i, k) += Pi_(i, j) * (Rj_(i, k) + mu_(i, j) * mu_(k, j));
    }
    for (int i = 0; i < m; ++i)
      for (int k = 0; k < m; ++k) Rn_(i, k) = same_anchor(i, k) ? var_(i, k) - nmean_(i) * nmean_(k) : 0.0;
    t.S += Rn_;  // (VI.2): weighted set covariance plus the mixed noise
    t.zhat += nmean_;
    if (!t.apply(
            y_, [this](VecX& r) { meas_.wrap_residual(r); }, this->x_, this->P_, res))
      Base::fail("Iukf.update: S");
    return res;
  }

  bool same_anchor(int i, int k) const { return i == k || meas_.row(i).anchor == meas_.row(k).anchor; }

  Meas meas_;
  situation::ForwardFilter fwd_;
  situation::ForwardFilter::Snapshot fsave_;  // step_quality restores it if the update throws
  SigmaScheme scheme_;
  SigmaWeights w_;
  detail::SigmaMoments<kDim> mom_;
  MatX Rn_, Rj_, mu_, var_, Pi_, onehot_;
  VecX nmean_, y_, speeds_;
  VecXi sj_;
  detail::UpdateTail<kDim> tail_;
};

}  // namespace nlosloc
