#pragma once
/// \file forward.hpp
/// Per-anchor HMM forward filter of the sight condition from the quality statistics alone (Huerta Sec. V-C,
/// eqs. 34-38; Grisales eq. 36 for N_z conditions). Anchors are treated independently (eq. 34): each keeps
/// gamma_{k,b,t} = P(s_{b,t} = k | o_{b,1:t}).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"

namespace nlosloc::situation {

/// Throws unless `gamma` is B x N_z with every row a probability vector (non-negative, summing to one
/// within 1e-9). `name` is the argument's name in the message.
inline void check_probabilities(const MatX& gamma, Eigen::Index B, Eigen::Index nz, const char* name) {
  nlosloc::detail::ensure_shape(gamma, B, nz, name);
  nlosloc::detail::ensure_finite(gamma, name);
  for (Eigen::Index b = 0; b < gamma.rows(); ++b)
    if (!(gamma.row(b).array() >= 0.0).all() || !(std::abs(gamma.row(b).sum() - 1.0) < 1e-9))
      nlosloc::detail::throw_invalid_argument(
          std::string(name) + ": every row must hold probabilities (>= 0) summing to 1; row " +
          std::to_string(b) + " does not");
}

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
    lrow_.resize(nz);
    T_.resize(nz, nz);
    reset();
    save(back_);  // sizes step()'s undo copy: steps never allocate, not even the first
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
    check_probabilities(gamma, num_anchors(), num_conditions(), "gamma");
    gamma_ = gamma;
    pred_ = gamma;  // the prior of the next update() (which starts from pred_)
  }

  /// Prediction (Huerta eq. 36): gamma_{k|t-1} = sum_m gamma_{m,t-1} P(s_t = k | s_{t-1} = m). `speeds`
  /// (size B, finite, >= 0) are the transversal speeds, needed only by speed-dependent chains (else may be
  /// empty). A rejected call changes nothing.
  void predict(const Eigen::Ref<const VecX>& speeds = VecX()) {
    const bool need = check_speeds(speeds);
    ++k_;
    for (int b = 0; b < num_anchors(); ++b) {
      process_.model(b).transition(k_, need ? speeds(b) : 0.0, T_);
      pred_.row(b).noalias() = gamma_.row(b) * T_;  // eq. (36)
    }
    gamma_ = pred_;
  }

  /// Update with the statistics o (size B; NaN = missing): gamma_k ∝ gamma_{k|t-1} p(o | s = k) (eq. 37),
  /// normalised so the probabilities of each anchor sum to one (eq. 38, N_z form). Returns
  /// log p(o_t | o_1:t-1) summed over anchors. Every anchor is computed before any is stored, so a
  /// rejected call (inf in o, or a statistic impossible under every condition) changes nothing.
  double update(const Eigen::Ref<const VecX>& o) {
    quality_.checked_table(o, num_anchors(), ll_);
    double total = 0.0;
    for (int b = 0; b < num_anchors(); ++b) {
      // log-domain product then normalise, so tiny densities do not underflow (weights in log space);
      // ll_ is overwritten with the unnormalised posterior
      const double m = ll_.row(b).maxCoeff();
      // An infinite density (Beta(a < 1) at 0) would give NaN weights and read as "impossible"
      NLOSLOC_ENSURE(m < std::numeric_limits<double>::infinity(),
                     "o: statistic of anchor " + std::to_string(b) +
                         " has an infinite density under some condition (the edge of its support, e.g. "
                         "Beta(a < 1) at 0); expected a statistic where every density is finite");
      double z = 0.0, shift = m;
      lrow_ = ll_.row(b);
      for (int k = 0; k < num_conditions(); ++k) {
        ll_(b, k) = pred_(b, k) * std::exp(lrow_(k) - m);  // eq. (37)
        z += ll_(b, k);
      }
      if (!(z >= std::numeric_limits<double>::min())) {
        // Underflow: the likeliest condition is (nearly) ruled out by the prediction, and the others lie
        // over ~708 nats below it. Rescale by the largest log pred + log p(o | k) instead.
        shift = -std::numeric_limits<double>::infinity();
        for (int k = 0; k < num_conditions(); ++k)
          if (pred_(b, k) > 0.0) shift = std::max(shift, std::log(pred_(b, k)) + lrow_(k));
        z = 0.0;
        for (int k = 0; k < num_conditions(); ++k) {
          ll_(b, k) = pred_(b, k) > 0.0 ? std::exp(std::log(pred_(b, k)) + lrow_(k) - shift) : 0.0;
          z += ll_(b, k);
        }
      }
      NLOSLOC_ENSURE(z > 0.0, "o: statistic of anchor " + std::to_string(b) +
                                  " is impossible under the predicted conditions");
      ll_.row(b) /= z;  // eq. (38): probabilities sum to one
      total += shift + std::log(z);
    }
    gamma_ = ll_;
    log_evidence_ = total;
    return total;
  }

  /// predict(speeds) then update(o); a rejected call (either argument) changes nothing.
  double step(const Eigen::Ref<const VecX>& o, const Eigen::Ref<const VecX>& speeds = VecX()) {
    check_statistics(o, num_anchors());
    check_speeds(speeds);
    save(back_);  // sized in the constructor: no allocation
    predict(speeds);
    try {
      return update(o);
    } catch (...) {
      restore(back_);  // a statistic with zero density under every predicted condition
      throw;
    }
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
  /// Restores a snapshot saved from this filter (or one of the same size). Checked first (the filter is
  /// unchanged on refusal, std::invalid_argument naming the field): gamma and pred B x N_z with rows of
  /// probabilities summing to 1, k >= 0, a finite log evidence (update() refuses a statistic of zero or
  /// infinite density, so the filter never holds another).
  void restore(const Snapshot& s) {
    check_probabilities(s.gamma, num_anchors(), num_conditions(), "snapshot.gamma");
    check_probabilities(s.pred, num_anchors(), num_conditions(), "snapshot.pred");
    NLOSLOC_ENSURE(s.k >= 0, "snapshot.k: expected a step index >= 0, got " + std::to_string(s.k));
    NLOSLOC_ENSURE(std::isfinite(s.log_evidence), "snapshot.log_evidence: expected a finite value, got " +
                                                      nlosloc::detail::fmt_shortest(s.log_evidence));
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
  /// Validates `speeds` for predict(): required when a chain is speed-dependent, else may be empty, and
  /// checked whenever given. Returns true when the chains need them.
  bool check_speeds(const Eigen::Ref<const VecX>& speeds) const {
    const bool need = process_.speed_dependent();
    if (!need && speeds.size() == 0) return false;
    nlosloc::detail::ensure_shape(speeds, num_anchors(), 1, "speeds");
    for (Eigen::Index b = 0; b < speeds.size(); ++b)
      if (!(speeds(b) >= 0.0) || !std::isfinite(speeds(b)))
        nlosloc::detail::throw_invalid_argument("speeds: expected finite values >= 0, got " +
                                                std::to_string(speeds(b)) + " at anchor " +
                                                std::to_string(b));
    return need;
  }

  MatX gamma_, pred_, ll_, T_;
  Eigen::RowVectorXd lrow_;  // update(): one anchor's log p(o | k) (no allocation)
  Snapshot back_;            // step()'s undo copy
  long k_ = 0;
  double log_evidence_ = 0.0;
};

}  // namespace nlosloc::situation
