#pragma once
/// \file chen.hpp
/// CHEN: the residual weighting algorithm ("Rwgh") of P.-C. Chen, "A non-line-of-sight error mitigation
/// algorithm in location estimation", IEEE WCNC 1999 (Huerta et al. 2009 ref. [10], baseline of Sec. VI-B).
///
/// Implemented form (Chen's published algorithm as it is generally stated):
///  1. For every combination S_k of anchors with at least `min_size` members (default: unknowns + 1, so
///     every combination is over-determined; Chen's TOA case: at least 3 BSs for 2 unknowns), the LOS ML
///     fix x_k of the rows of S_k and its residual R_k = sum_{i in S_k} ((y_i - g_i(x_k) - mu_i)/sigma_i)^2.
///  2. The normalised residual R~_k = R_k / |S_k| (Chen normalises by the size of the combination).
///  3. Huerta Sec. VI-B: "50% of the combinations are rejected": the fraction `reject_fraction` of the
///     combinations with the largest R~_k is discarded.
///  4. The estimate is the residual-weighted average x = sum_k x_k / R~_k / sum_k 1/R~_k over the rest.
/// Deviations: the per-combination ML fix uses damped Gauss-Newton (gauss_newton.hpp) warm-started from
/// the combination's previous fix, with the closed-form linear LS as start on the first epoch and as a
/// retry, where Huerta used simulated annealing [45]; residuals are weighted by the LOS sigmas (identical
/// to Chen's unweighted residual when all rows have the same LOS variance, as in H2). The clock bias of RTOA
/// rows is one more unknown of every fix and is averaged like the position.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "nlosloc/snapshot/gauss_newton.hpp"
#include "nlosloc/snapshot/result.hpp"

namespace nlosloc::snapshot {

/// Options of Chen.
struct ChenOptions {
  int min_size = -1;             ///< smallest combination (anchors); -1: unknowns + 1
  double reject_fraction = 0.5;  ///< fraction of combinations with the largest residual rejected, [0, 1)
  double residual_floor = 1e-9;  ///< lower bound of R~_k in the weights 1/R~_k
};

/// Chen 1999 residual weighting (see the file comment for the exact form).
class Chen {
 public:
  Chen(const MeasurementStack& stack, const ChenOptions& opt = {}, const GaussNewtonOptions& gn = {})
      : solver_(stack, gn), opt_(opt) {
    const int B = stack.num_anchors();
    const int min_size = opt.min_size >= 0 ? opt.min_size : solver_.unknowns() + 1;
    NLOSLOC_ENSURE(min_size >= 1 && min_size <= B, "opt.min_size: expected 1 <= min_size <= anchors (" +
                                                       std::to_string(B) + "), got " +
                                                       std::to_string(min_size));
    NLOSLOC_ENSURE(opt.reject_fraction >= 0.0 && opt.reject_fraction < 1.0,
                   "opt.reject_fraction: expected a value in [0, 1)");
    // inf would make every weight 1 / inf = 0, and the combined fix 0 / 0
    NLOSLOC_ENSURE(std::isfinite(opt.residual_floor) && opt.residual_floor > 0.0,
                   "opt.residual_floor: expected a finite value > 0");
    subsets_ = subsets_at_least(B, min_size);
    start_.assign(subsets_.size(), Theta());
    fixes_.resize(subsets_.size());
    score_.resize(subsets_.size());
    order_.resize(subsets_.size());
    use_.resize(subsets_.size());
    for (std::size_t k = 0; k < subsets_.size(); ++k) solver_.rows_of(subsets_[k], use_[k]);
    res_.sight.setZero(B);
    reset(Theta::Zero(solver_.unknowns()));
  }

  const LosSolver& solver() const { return solver_; }
  const ChenOptions& options() const { return opt_; }
  /// The combinations (anchor masks), larger first.
  const std::vector<AnchorMask>& combinations() const { return subsets_; }
  bool classifies_sight() const { return false; }
  const VecXi& sight() const { return res_.sight; }

  /// Sets the start of every combination's fix (position, then clock bias) and forgets warm starts.
  void reset(const Theta& start) {
    detail::ensure_shape(start, solver_.unknowns(), 1, "start");
    detail::ensure_finite(start, "start");
    for (auto& s : start_) s = start;
    res_.theta = start;
    first_ = true;
  }

  /// The weighted estimate of epoch y.
  const SnapshotResult& solve(const Eigen::Ref<const VecX>& y) {
    detail::check_measurement(y, solver_.stack().rows());  // before res_ changes
    res_.fixes = 0;
    res_.valid = false;
    std::size_t n = 0;
    for (std::size_t k = 0; k < subsets_.size(); ++k) {
      Fix f = solver_.solve(y, start_[k], use_[k], solver_.los_noise());
      ++res_.fixes;
      Theta lin;
      if ((first_ || !f.converged) && solver_.linear_start(y, use_[k], lin)) {
        const Fix g = solver_.solve(y, lin, use_[k], solver_.los_noise());
        ++res_.fixes;
        if (!(f.cost <= g.cost)) f = g;
      }
      fixes_[k] = f;
      const int rows = f.rows;
      const bool ok = rows > solver_.unknowns() && std::isfinite(f.cost) && f.theta.allFinite();
      if (ok) start_[k] = f.theta;
      score_[k] = ok ? f.cost / rows : std::numeric_limits<double>::infinity();  // R~_k = R_k / |S_k|
      if (ok) ++n;
    }
    if (n > 0) {
      std::iota(order_.begin(), order_.end(), std::size_t{0});
      std::stable_sort(order_.begin(), order_.end(),
                       [this](std::size_t a, std::size_t b) { return score_[a] < score_[b]; });
      // Keep the (1 - reject_fraction) share with the smallest residual (at least one).
      const auto keep = std::max<std::size_t>(
          1, static_cast<std::size_t>(std::ceil((1.0 - opt_.reject_fraction) * static_cast<double>(n))));
      Theta acc = Theta::Zero(solver_.unknowns());
      double wsum = 0.0;
      for (std::size_t j = 0; j < keep; ++j) {
        const std::size_t k = order_[j];
        const double w = 1.0 / std::max(score_[k], opt_.residual_floor);  // Chen's weight 1/R~_k
        acc += w * fixes_[k].theta;
        wsum += w;
      }
      res_.theta = acc / wsum;
      res_.cost = score_[order_[0]];
      res_.valid = true;
      first_ = false;
    }
    return res_;
  }

 private:
  LosSolver solver_;
  ChenOptions opt_;
  std::vector<AnchorMask> subsets_;
  std::vector<Theta> start_;
  std::vector<Fix> fixes_;
  std::vector<double> score_;
  std::vector<std::size_t> order_;
  std::vector<std::vector<char>> use_;
  SnapshotResult res_;
  bool first_ = true;
};

}  // namespace nlosloc::snapshot
