#pragma once
/// \file forward.hpp
/// Per-anchor HMM forward filter of the sight condition from the quality statistics alone (Huerta Sec. V-C,
/// eqs. 34-38; Grisales eq. 36 for N_z conditions). Anchors are treated independently (eq. 34): each keeps
/// gamma_{k,b,t} = P(s_{b,t} = k | o_{b,1:t}).
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"

namespace nlosloc::situation {

/// Grid-based (forward) filter of every anchor's sight condition.
class ForwardFilter {
 public:
  /// `process`: the sight chains (B anchors); `quality`: p(o | s), same N_z.
  ForwardFilter(SightProcess process, QualityModel quality)
      : process_(std::move(process)), quality_(std::move(quality)) {
    NLOSLOC_ENSURE(process_.num_anchors() >= 1, "process: expected at least one anchor");
    NLOSLOC_ENSURE(quality_.num_conditions() == process_.num_conditions(),
                   "quality: expected " + std::to_string(process_.num_conditions()) +
                       " conditions (as the sight process), got " +
                       std::to_string(quality_.num_conditions()));
    const int B = num_anchors(), nz = num_conditions();
    gamma_.resize(B, nz);
    pred_.resize(B, nz);
    ll_.resize(B, nz);
    T_.resize(nz, nz);
    reset();
  }

  int num_anchors() const { return process_.num_anchors(); }
  int num_conditions() const { return process_.num_conditions(); }
  const SightProcess& process() const { return process_; }
  const QualityModel& quality() const { return quality_; }
  /// Steps taken since reset (the k of the next predict is step() + 1).
  long step_index() const { return k_; }

  /// Back to the priors of the chains (s_0) and step 0.
  void reset() {
    for (int b = 0; b < num_anchors(); ++b) gamma_.row(b) = process_.model(b).initial().transpose();
    pred_ = gamma_;
    k_ = 0;
    log_evidence_ = 0.0;
  }
  /// Replaces the probabilities (B x N_z, rows non-negative summing to one).
  void set_probabilities(const MatX& gamma) {
    nlosloc::detail::ensure_shape(gamma, num_anchors(), num_conditions(), "gamma");
    nlosloc::detail::ensure_finite(gamma, "gamma");
    for (Eigen::Index b = 0; b < gamma.rows(); ++b)
      NLOSLOC_ENSURE((gamma.row(b).array() >= 0.0).all() && std::abs(gamma.row(b).sum() - 1.0) < 1e-9,
                     "gamma: every row must hold probabilities summing to 1");
    gamma_ = gamma;
  }

  /// Prediction (Huerta eq. 36): gamma_{k|t-1} = sum_m gamma_{m,t-1} P(s_t = k | s_{t-1} = m). `speeds`
  /// (size B) are the transversal speeds, needed only by speed-dependent chains (else may be empty).
  void predict(const Eigen::Ref<const VecX>& speeds = VecX()) {
    const bool need = process_.speed_dependent();
    if (need) nlosloc::detail::ensure_shape(speeds, num_anchors(), 1, "speeds");
    ++k_;
    for (int b = 0; b < num_anchors(); ++b) {
      process_.model(b).transition(k_, need ? speeds(b) : 0.0, T_);
      pred_.row(b).noalias() = gamma_.row(b) * T_;  // eq. (36)
    }
    gamma_ = pred_;
  }

  /// Update with the statistics o (size B; NaN = missing): gamma_k ∝ gamma_{k|t-1} p(o | s = k) (eq. 37),
  /// normalised so the probabilities of each anchor sum to one (eq. 38, N_z form). Returns
  /// log p(o_t | o_1:t-1) summed over anchors.
  double update(const Eigen::Ref<const VecX>& o) {
    nlosloc::detail::ensure_shape(o, num_anchors(), 1, "o");
    quality_.log_likelihood_table(o, ll_);
    double total = 0.0;
    for (int b = 0; b < num_anchors(); ++b) {
      // log-domain product then normalise, so tiny densities do not underflow (weights in log space)
      const double m = ll_.row(b).maxCoeff();
      if (!std::isfinite(m)) {
        nlosloc::detail::throw_invalid_argument("o: statistic of anchor " + std::to_string(b) +
                                                " has zero density under every condition");
      }
      double z = 0.0;
      for (int k = 0; k < num_conditions(); ++k) {
        gamma_(b, k) = pred_(b, k) * std::exp(ll_(b, k) - m);  // eq. (37)
        z += gamma_(b, k);
      }
      NLOSLOC_ENSURE(z > 0.0, "o: statistic of anchor " + std::to_string(b) +
                                  " is impossible under the predicted conditions");
      gamma_.row(b) /= z;  // eq. (38): probabilities sum to one
      total += m + std::log(z);
    }
    log_evidence_ = total;
    return total;
  }

  /// predict(speeds) then update(o).
  double step(const Eigen::Ref<const VecX>& o, const Eigen::Ref<const VecX>& speeds = VecX()) {
    predict(speeds);
    return update(o);
  }

  /// The mutable part of the filter (probabilities, step, evidence): lets an embedding filter undo a step
  /// without copying the chains. A Snapshot filled once keeps its buffers: later saves do not allocate.
  struct Snapshot {
    MatX gamma, pred;
    long k = 0;
    double log_evidence = 0.0;
  };
  void save(Snapshot& s) const {
    s.gamma = gamma_;
    s.pred = pred_;
    s.k = k_;
    s.log_evidence = log_evidence_;
  }
  /// Restores a snapshot saved from this filter (or one of the same size).
  void restore(const Snapshot& s) {
    nlosloc::detail::ensure_shape(s.gamma, num_anchors(), num_conditions(), "snapshot.gamma");
    nlosloc::detail::ensure_shape(s.pred, num_anchors(), num_conditions(), "snapshot.pred");
    gamma_ = s.gamma;
    pred_ = s.pred;
    k_ = s.k;
    log_evidence_ = s.log_evidence;
  }

  /// gamma (B x N_z): P(s_b = k | o_b,1:t) after the last update (eq. 35).
  const MatX& probabilities() const { return gamma_; }
  /// Predicted probabilities gamma_{t|t-1} of the last predict (eq. 36).
  const MatX& predicted() const { return pred_; }
  /// log p(o_t | o_1:t-1) of the last update.
  double last_log_evidence() const { return log_evidence_; }
  /// Most probable condition of every anchor.
  VecXi argmax() const {
    VecXi s(num_anchors());
    for (int b = 0; b < num_anchors(); ++b) gamma_.row(b).maxCoeff(&s(b));
    return s;
  }

 private:
  SightProcess process_;
  QualityModel quality_;
  MatX gamma_, pred_, ll_, T_;
  long k_ = 0;
  double log_evidence_ = 0.0;
};

}  // namespace nlosloc::situation
