#pragma once
/// \file estimator.hpp
/// Puts a snapshot baseline (MleLos, Chen, Cong, Urruela: reset(start), solve(y), sight()) behind the
/// sim::Estimator interface used by the Monte Carlo runner and the bench.
#include <memory>
#include <string>
#include <utility>

#include "nlosloc/sim/scenario.hpp"
#include "nlosloc/snapshot/chen.hpp"
#include "nlosloc/snapshot/cong.hpp"
#include "nlosloc/snapshot/mle_los.hpp"
#include "nlosloc/snapshot/urruela.hpp"

namespace nlosloc::sim {

/// A snapshot solver as an Estimator. reset() starts every fix from the draw's initial mean (position and,
/// for RTOA, clock bias); step k solves epoch k alone and writes the position. When an epoch has no fix the
/// previous position is repeated.
template <class Solver>
class SnapshotEstimator final : public Estimator {
 public:
  SnapshotEstimator(std::string name, Solver solver) : name_(std::move(name)), solver_(std::move(solver)) {}

  std::string name() const override { return name_; }

  void reset(const Draw& d, Rng& /*rng: deterministic*/) override {
    const StateLayout& L = solver_.solver().stack().layout();
    detail::ensure_shape(d.initial_mean, L.dim, 1, "draw.initial_mean");
    snapshot::Theta start(solver_.solver().unknowns());
    start.head(L.space_dim) = d.initial_mean.segment(L.position, L.space_dim);
    if (solver_.solver().has_clock()) start[L.space_dim] = d.initial_mean[L.clock_bias];
    solver_.reset(start);
  }

  void step(int /*k*/, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& /*o*/,
            Eigen::Ref<VecX> position_out) override {
    const snapshot::SnapshotResult& r = solver_.solve(y);
    position_out = r.theta.head(position_out.size());
  }

  bool estimates_sight() const override { return solver_.classifies_sight(); }
  void sight_estimate(Eigen::Ref<VecXi> out) const override { out = solver_.sight(); }

  const Solver& solver() const { return solver_; }

 private:
  std::string name_;
  Solver solver_;
};

/// unique_ptr<Estimator> holding a SnapshotEstimator<Solver>.
template <class Solver>
std::unique_ptr<Estimator> make_snapshot_estimator(std::string name, Solver solver) {
  return std::make_unique<SnapshotEstimator<Solver>>(std::move(name), std::move(solver));
}

}  // namespace nlosloc::sim
