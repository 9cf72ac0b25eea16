#pragma once
/// \file cong.hpp
/// CONG: NLOS mitigation of L. Cong and W. Zhuang, "Nonline-of-sight error mitigation in mobile location",
/// IEEE Trans. Wireless Commun. 4(2), 2005 (Huerta et al. 2009 ref. [14], baseline of Sec. VI-B).
///
/// Implemented form (as Huerta Sec. II-D summarises [14] and as the method is generally stated): NLOS
/// anchors are identified by a residual test and discarded; if too few LOS anchors remain, the NLOS
/// measurements with the smallest residuals are kept with their error modelled by an asymmetric (split)
/// Gaussian fitted to the NLOS error. Precisely, per epoch:
///  1. Residual test. For k = B, B-1, ..., min_los (default unknowns + 1, the smallest set whose
///     consistency can be tested): every anchor set S of size k gets its LOS ML fix (gauss_newton.hpp) and
///     passes when (a) its cost (chi-square with rows(S) - unknowns degrees of freedom under LOS) is below
///     the `confidence` quantile and (b) every anchor outside S has a residual y - g - mu above
///     -negative_sigmas * sigma (NLOS errors are positive, the point of [14] over [10]). The first k with a
///     passing set stops the search; its smallest-cost passing set is the LOS set.
///  2. Enough LOS anchors (a set was found): the estimate is the LOS ML fix of that set; the other anchors
///     are declared NLOS.
///  3. Too few: the fix of all anchors under LOS ranks the rows by normalised residual; the `min_rows`
///     (default unknowns + 1) rows with the smallest residuals are kept, each with the split normal
///     noise::AsymmetricNormal::fit of `fit_samples` draws of the row's NLOS noise (condition 1 of the
///     stack, fitted once at construction with a fixed seed), and the ML fix under that model is the
///     estimate (Huerta Sec. VI-B: "the asymmetric Gaussian pdf is used to fit as likely as possible the
///     Rayleigh distribution"); every anchor is declared NLOS.
/// The per-set fix uses damped Gauss-Newton warm-started from the set's previous fix, with the closed-form
/// linear LS as the first start and as a retry.
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "nlosloc/core/random.hpp"
#include "nlosloc/models/noise.hpp"
#include "nlosloc/snapshot/gauss_newton.hpp"
#include "nlosloc/snapshot/result.hpp"

namespace nlosloc::snapshot {

/// Options of Cong.
struct CongOptions {
  double confidence = 0.99;       ///< residual test: chi-square quantile level, in (0, 1)
  double negative_sigmas = 3.0;   ///< residual test: discarded anchors' residuals must exceed -this * sigma
  int min_los = -1;               ///< smallest LOS set tested; -1: unknowns + 1
  int min_rows = -1;              ///< rows kept when too few LOS anchors; -1: unknowns + 1
  int fit_samples = 20000;        ///< draws of each row's NLOS noise for the asymmetric Gaussian fit (>= 3)
  std::uint64_t fit_seed = 2005;  ///< seed of those draws
};

/// Cong & Zhuang 2005 (see the file comment for the exact form).
class Cong {
 public:
  Cong(const MeasurementStack& stack, const CongOptions& opt = {}, const GaussNewtonOptions& gn = {})
      : solver_(stack, gn), opt_(opt) {
    const int B = stack.num_anchors(), m = stack.rows(), n = solver_.unknowns();
    NLOSLOC_ENSURE(stack.num_conditions() >= 2,
                   "stack: CONG needs an NLOS noise (condition 1) per row to fit the asymmetric Gaussian");
    NLOSLOC_ENSURE(opt.confidence > 0.0 && opt.confidence < 1.0,
                   "opt.confidence: expected a value in (0, 1)");
    NLOSLOC_ENSURE(opt.negative_sigmas > 0.0, "opt.negative_sigmas: expected > 0");
    NLOSLOC_ENSURE(opt.fit_samples >= 3, "opt.fit_samples: expected >= 3");
    min_los_ = opt.min_los >= 0 ? opt.min_los : n + 1;
    min_rows_ = opt.min_rows >= 0 ? opt.min_rows : n + 1;
    NLOSLOC_ENSURE(min_los_ >= 1 && min_los_ <= B, "opt.min_los: expected 1 <= min_los <= anchors (" +
                                                       std::to_string(B) + "), got " +
                                                       std::to_string(min_los_));
    NLOSLOC_ENSURE(min_rows_ >= n && min_rows_ <= m, "opt.min_rows: expected unknowns <= min_rows <= rows (" +
                                                         std::to_string(m) + "), got " +
                                                         std::to_string(min_rows_));
    subsets_ = subsets_at_least(B, min_los_);
    start_.assign(subsets_.size(), Theta());
    use_.resize(subsets_.size());
    for (std::size_t k = 0; k < subsets_.size(); ++k) solver_.rows_of(subsets_[k], use_[k]);
    // chi-square thresholds per degrees of freedom 1..m.
    chi2_.assign(static_cast<std::size_t>(m + 1), 0.0);
    for (int d = 1; d <= m; ++d)
      chi2_[static_cast<std::size_t>(d)] =
          boost::math::quantile(boost::math::chi_squared_distribution<double>(d), opt.confidence);
    // Asymmetric Gaussian fit of each row's NLOS noise (Cong & Zhuang 2005; noise::AsymmetricNormal::fit).
    Rng rng(opt.fit_seed);
    VecX draws(opt.fit_samples);
    nlos_.resize(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i) {
      const auto& d = stack.noise(i, 1);
      for (int s = 0; s < opt.fit_samples; ++s) draws[s] = d.sample(rng);
      nlos_[static_cast<std::size_t>(i)] = RowNoise::split(noise::AsymmetricNormal::fit(draws));
    }
    mixed_ = solver_.los_noise();
    r_.setZero(m);
    rank_.resize(static_cast<std::size_t>(m));
    keep_.assign(static_cast<std::size_t>(m), 0);
    res_.sight.setZero(B);
    reset(Theta::Zero(n));
  }

  const LosSolver& solver() const { return solver_; }
  const CongOptions& options() const { return opt_; }
  /// The fitted split normal of each row's NLOS noise.
  const std::vector<RowNoise>& nlos_noise() const { return nlos_; }
  bool classifies_sight() const { return true; }
  /// Sight decision of the last epoch (0 LOS set, 1 otherwise).
  const VecXi& sight() const { return res_.sight; }
  /// True when the last epoch found a consistent LOS set (step 2), false for step 3.
  bool enough_los() const { return enough_; }

  void reset(const Theta& start) {
    detail::ensure_shape(start, solver_.unknowns(), 1, "start");
    detail::ensure_finite(start, "start");
    for (auto& s : start_) s = start;
    res_.theta = start;
    first_ = true;
  }

  const SnapshotResult& solve(const Eigen::Ref<const VecX>& y) {
    detail::check_measurement(y, solver_.stack().rows());  // before res_ changes
    const int n = solver_.unknowns(), m = solver_.stack().rows();
    res_.fixes = 0;
    res_.valid = false;
    enough_ = false;
    int best = -1;
    Fix best_fix;
    Theta all_fix;
    bool have_all = false;
    int size = -1;
    for (std::size_t k = 0; k < subsets_.size(); ++k) {
      const int sz = mask_count(subsets_[k]);
      if (best >= 0 && sz < size) break;  // a passing set of a larger size was found
      size = sz;
      Fix f = fix(y, k);
      if (!(f.rows > 0 && std::isfinite(f.cost))) continue;
      if (k == 0) {
        all_fix = f.theta;
        have_all = true;
      }
      if (!passes(y, f, k)) continue;
      if (best < 0 || f.cost < best_fix.cost) {
        best = static_cast<int>(k);
        best_fix = f;
      }
    }
    if (best >= 0) {  // step 2: LOS ML fix of the LOS set
      enough_ = true;
      res_.theta = best_fix.theta;
      res_.cost = best_fix.cost;
      res_.valid = true;
      for (int b = 0; b < res_.sight.size(); ++b)
        res_.sight[b] = ((subsets_[static_cast<std::size_t>(best)] >> b) & 1U) ? 0 : 1;
      first_ = false;
      return res_;
    }
    if (!have_all) return res_;
    // Step 3: keep the min_rows rows with the smallest normalised residual, split-normal NLOS model.
    solver_.residuals(y, all_fix, r_);
    int avail = 0;
    for (int i = 0; i < m; ++i) {
      rank_[static_cast<std::size_t>(i)] = i;
      avail += !std::isnan(y[i]);
    }
    const auto& los = solver_.los_noise();
    std::stable_sort(rank_.begin(), rank_.end(), [&](int a, int b) {
      const double za = std::isnan(y[a]) ? kInf : los[static_cast<std::size_t>(a)].normalized(r_[a]);
      const double zb = std::isnan(y[b]) ? kInf : los[static_cast<std::size_t>(b)].normalized(r_[b]);
      return za < zb;
    });
    std::fill(keep_.begin(), keep_.end(), 0);
    const int take = std::min(min_rows_, avail);
    for (int j = 0; j < take; ++j) {
      const auto i = static_cast<std::size_t>(rank_[static_cast<std::size_t>(j)]);
      keep_[i] = 1;
      mixed_[i] = nlos_[i];
    }
    if (take >= n) {
      const Fix f = solver_.solve(y, all_fix, keep_, mixed_);
      ++res_.fixes;
      if (std::isfinite(f.cost) && f.theta.allFinite()) {
        res_.theta = f.theta;
        res_.cost = f.cost;
        res_.valid = true;
        first_ = false;
      }
    }
    mixed_ = los;
    res_.sight.setOnes();
    return res_;
  }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();

  Fix fix(const Eigen::Ref<const VecX>& y, std::size_t k) {
    Fix f = solver_.solve(y, start_[k], use_[k], solver_.los_noise());
    ++res_.fixes;
    Theta lin;
    if ((first_ || !f.converged) && solver_.linear_start(y, use_[k], lin)) {
      const Fix g = solver_.solve(y, lin, use_[k], solver_.los_noise());
      ++res_.fixes;
      if (!(f.cost <= g.cost)) f = g;
    }
    if (std::isfinite(f.cost) && f.theta.allFinite()) start_[k] = f.theta;
    return f;
  }

  /// Residual test of set k (see the file comment, step 1).
  bool passes(const Eigen::Ref<const VecX>& y, const Fix& f, std::size_t k) {
    const int dof = f.rows - solver_.unknowns();
    if (dof < 1 || f.cost > chi2_[static_cast<std::size_t>(dof)]) return false;
    solver_.residuals(y, f.theta, r_);
    const auto& los = solver_.los_noise();
    for (int i = 0; i < solver_.stack().rows(); ++i) {
      if (use_[k][static_cast<std::size_t>(i)] || std::isnan(y[i])) continue;
      if (los[static_cast<std::size_t>(i)].normalized(r_[i]) < -opt_.negative_sigmas) return false;
    }
    return true;
  }

  LosSolver solver_;
  CongOptions opt_;
  int min_los_ = 0, min_rows_ = 0;
  std::vector<AnchorMask> subsets_;
  std::vector<Theta> start_;
  std::vector<std::vector<char>> use_;
  std::vector<double> chi2_;
  std::vector<RowNoise> nlos_, mixed_;
  VecX r_;
  std::vector<int> rank_;
  std::vector<char> keep_;
  SnapshotResult res_;
  bool first_ = true, enough_ = false;
};

}  // namespace nlosloc::snapshot
