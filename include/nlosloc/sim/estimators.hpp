#pragma once
/// \file estimators.hpp
/// Adapters that put the compile-time filters (KF, EKF, UKF, ...) behind the sim::Estimator interface:
/// one virtual call per step, the filter's own code fully inlined inside.
#include <memory>
#include <string>
#include <utility>

#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc::sim {

/// Which sight vector a Gaussian filter is given at each update.
enum class SightPolicy {
  kAssumeLos = 0,  ///< no sight passed: every anchor in condition 0 (the "EKF-LOS" of the papers)
  kOracle = 1      ///< the draw's true sight (an upper bound, not a practical estimator)
};

/// Runs a Gaussian filter (anything with kDim, set_belief, predict, update, mean, like Ekf and Ukf) as an
/// Estimator. The filter is constructed once by the caller; reset() replaces its belief with the draw's
/// initial belief at t = 0; step 0 updates only, later steps predict then update (scenario.hpp).
template <class Filter>
class GaussianFilterEstimator final : public Estimator {
 public:
  static constexpr int kDim = Filter::kDim;

  /// `position` / `space_dim`: where the position sits in the filter's state (StateLayout).
  GaussianFilterEstimator(std::string name, Filter filter, SightPolicy sight = SightPolicy::kAssumeLos)
      : name_(std::move(name)),
        filter_(std::move(filter)),
        policy_(sight),
        position_(filter_.measurements().layout().position),
        space_dim_(filter_.measurements().layout().space_dim) {
    sight_.setZero(filter_.measurements().num_anchors());
  }

  std::string name() const override { return name_; }

  void reset(const Draw& d, Rng& /*rng: deterministic filter*/) override {
    detail::ensure_shape(d.initial_mean, kDim, 1, "draw.initial_mean");
    detail::ensure_shape(d.initial_cov, kDim, kDim, "draw.initial_cov");
    filter_.set_belief(Gaussian<kDim>(d.initial_mean, d.initial_cov), 0.0);
    draw_ = &d;
  }

  void step(int k, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& /*o*/,
            Eigen::Ref<VecX> position_out) override {
    const VecXi* sight = nullptr;
    if (policy_ == SightPolicy::kOracle) {
      sight_ = draw_->sight.row(k).transpose();
      sight = &sight_;
    }
    if (k > 0) {
      filter_.step(y, sight);  // predict + update (belief restored if the update throws)
    } else {
      filter_.update(y, sight);  // the initial belief is already at t_0
    }
    position_out = filter_.mean().segment(position_, space_dim_);
  }

  const Filter& filter() const { return filter_; }

 private:
  std::string name_;
  Filter filter_;
  SightPolicy policy_;
  int position_, space_dim_;
  VecXi sight_;
  const Draw* draw_ = nullptr;
};

/// unique_ptr<Estimator> holding a GaussianFilterEstimator<Filter>.
template <class Filter>
std::unique_ptr<Estimator> make_filter_estimator(std::string name, Filter filter,
                                                 SightPolicy sight = SightPolicy::kAssumeLos) {
  return std::make_unique<GaussianFilterEstimator<Filter>>(std::move(name), std::move(filter), sight);
}

}  // namespace nlosloc::sim
