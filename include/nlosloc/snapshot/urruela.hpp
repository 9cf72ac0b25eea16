#pragma once
/// \file urruela.hpp
/// URR: NLOS mitigation by ML detection of the LOS/NLOS hypothesis (J. Riba and A. Urruela, "A
/// non-line-of-sight mitigation technique based on ML-detection", ICASSP 2004, Huerta ref. [15]) extended to
/// a trellis (Viterbi) search over time (A. Urruela, H. Morata and J. Riba, "NLOS mitigation based on a
/// trellis search for wireless communications", SPAWC 2005, Huerta ref. [17]), on TDOA measurements
/// (Huerta Sec. VI-B: "uses TDOA measures instead of RTOA ones").
///
/// Implemented form. A hypothesis h is the set L of LOS anchors (|L| >= D + 1, so that the |L| - 1 TDOAs
/// fix the D-dimensional position); NLOS anchors are discarded (URR does not characterise the NLOS noise,
/// Huerta Sec. VI-B). Per epoch t and hypothesis h:
///  - the ML position from the TDOAs of the anchors in L (reference: any anchor of L). Computed as the
///    ML fix of their pseudoranges with the clock bias as a free nuisance unknown, which is the same
///    estimator: minimising over tau profiles out the common offset exactly, and the profiled cost
///    sum ((r_i - tau)/sigma_i)^2 equals the TDOA quadratic form d^T C^-1 d of the correlated TDOA noise;
///  - the branch metric (negative log-likelihood) m_t(h) = 1/2 [chi2_h + (|L| - 1) log 2 pi +
///    sum_{i in L} log sigma_i^2 + log sum_{i in L} sigma_i^-2] + |N_h| log W: the Gaussian density of the
///    |L| - 1 TDOAs (det C = prod sigma_i^2 sum sigma_i^-2) times a uniform density 1/W on [0, W] for each
///    discarded NLOS measurement (an uninformative NLOS model; W = `nlos_span`);
///  - Viterbi recursion delta_t(h) = m_t(h) + min_h' [delta_{t-1}(h') - log P(h | h')] with independent
///    per-anchor two-state transitions (p_ln, p_nl) and the prior P(h_0) from p_nlos.
/// The estimate at t is the fix of the hypothesis with the smallest delta_t (the trellis decision without
/// delay, as a tracker must output every epoch). Deviations: the per-hypothesis fixes use damped
/// Gauss-Newton warm-started from the hypothesis' previous fix (closed-form linear LS on the first epoch /
/// retry) instead of the closed-form hyperbolic ML of Urruela & Riba (ICASSP 2004, Huerta ref. [16]).
/// The stack must hold one RTOA (or TOA) row per anchor; TDOAs are formed from them.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "nlosloc/snapshot/gauss_newton.hpp"
#include "nlosloc/snapshot/result.hpp"

namespace nlosloc::snapshot {

/// Options of Urruela.
struct UrruelaOptions {
  double p_nlos = 0.5;       ///< prior probability of NLOS per anchor at t = 0, in (0, 1)
  double p_ln = 0.005;       ///< per-step P(LOS -> NLOS), in (0, 1)
  double p_nl = 0.005;       ///< per-step P(NLOS -> LOS), in (0, 1)
  double nlos_span = 300.0;  ///< W (m): an NLOS measurement is taken as uniform over a span W
};

/// Riba & Urruela ML detection with the Urruela-Morata-Riba trellis search (see the file comment).
class Urruela {
 public:
  Urruela(const MeasurementStack& stack, const UrruelaOptions& opt = {}, const GaussNewtonOptions& gn = {})
      : solver_(stack, gn), opt_(opt) {
    const int B = stack.num_anchors(), D = stack.layout().space_dim;
    NLOSLOC_ENSURE(stack.rows() == B, "stack: URR expects one RTOA/TOA row per anchor, got " +
                                          std::to_string(stack.rows()) + " rows for " + std::to_string(B) +
                                          " anchors");
    for (int i = 0; i < B; ++i) {
      const MeasurementRow& r = stack.row(i);
      NLOSLOC_ENSURE(
          (r.kind == RowKind::kRtoa || r.kind == RowKind::kToa) && r.anchor == i,
          "stack: row " + std::to_string(i) + " must be the TOA/RTOA row of anchor " + std::to_string(i));
    }
    NLOSLOC_ENSURE(B <= 16, "stack: URR enumerates 2^B hypotheses; expected at most 16 anchors");
    auto prob = [](double p, const char* name) {
      NLOSLOC_ENSURE(p > 0.0 && p < 1.0, std::string(name) + ": expected a probability in (0, 1)");
    };
    prob(opt.p_nlos, "opt.p_nlos");
    prob(opt.p_ln, "opt.p_ln");
    prob(opt.p_nl, "opt.p_nl");
    detail::ensure_positive(opt.nlos_span, "opt.nlos_span");
    // With TOA rows (no clock unknown) the TDOA equivalence needs the clock: use the RTOA form only.
    NLOSLOC_ENSURE(solver_.has_clock(), "stack: URR needs RTOA rows (a clock bias to difference out)");
    hyp_ = subsets_at_least(B, D + 1);
    NLOSLOC_ENSURE(!hyp_.empty(), "stack: URR needs at least D + 1 anchors");
    const std::size_t H = hyp_.size();
    start_.assign(H, Theta());
    fixes_.resize(H);
    metric_.resize(H);
    delta_.resize(H);
    prev_.resize(H);
    use_.resize(H);
    for (std::size_t h = 0; h < H; ++h) solver_.rows_of(hyp_[h], use_[h]);
    const auto& los = solver_.los_noise();
    log_sig2_.resize(static_cast<std::size_t>(B));
    for (int i = 0; i < B; ++i)
      log_sig2_[static_cast<std::size_t>(i)] = 2.0 * std::log(los[static_cast<std::size_t>(i)].sigma_left);
    // -log transition per anchor: [from LOS][to LOS/NLOS], [from NLOS][to LOS/NLOS].
    c_ll_ = -std::log1p(-opt.p_ln);
    c_ln_ = -std::log(opt.p_ln);
    c_nl_ = -std::log(opt.p_nl);
    c_nn_ = -std::log1p(-opt.p_nl);
    all_ = (AnchorMask{1} << B) - 1;
    res_.sight.setZero(B);
    reset(Theta::Zero(solver_.unknowns()));
  }

  const LosSolver& solver() const { return solver_; }
  /// The options it was built with (prior, switch probabilities, NLOS span).
  const UrruelaOptions& options() const { return opt_; }
  /// The hypotheses (LOS anchor masks), larger LOS sets first.
  const std::vector<AnchorMask>& hypotheses() const { return hyp_; }
  bool classifies_sight() const { return true; }
  const VecXi& sight() const { return res_.sight; }
  /// Accumulated Viterbi metrics delta_t(h) (minimum 0) after the last epoch.
  const std::vector<double>& path_metrics() const { return delta_; }

  void reset(const Theta& start) {
    detail::ensure_shape(start, solver_.unknowns(), 1, "start");
    detail::ensure_finite(start, "start");
    for (auto& s : start_) s = start;
    res_.theta = start;
    first_ = true;
  }

  const SnapshotResult& solve(const Eigen::Ref<const VecX>& y) {
    detail::check_measurement(y, solver_.stack().rows());  // before res_ changes
    const std::size_t H = hyp_.size();
    const int B = solver_.stack().num_anchors();
    const double log2pi = std::log(2.0 * kPi), logW = std::log(opt_.nlos_span);
    res_.fixes = 0;
    bool any = false;
    for (std::size_t h = 0; h < H; ++h) {
      Fix f = solver_.solve(y, start_[h], use_[h], solver_.los_noise());
      ++res_.fixes;
      Theta lin;
      if ((first_ || !f.converged) && solver_.linear_start(y, use_[h], lin)) {
        const Fix g = solver_.solve(y, lin, use_[h], solver_.los_noise());
        ++res_.fixes;
        if (!(f.cost <= g.cost)) f = g;
      }
      fixes_[h] = f;
      const int nl = f.rows;  // LOS rows actually observed
      if (nl < solver_.space_dim() + 1 || !std::isfinite(f.cost) || !f.theta.allFinite()) {
        metric_[h] = kInf;
        continue;
      }
      start_[h] = f.theta;
      double logdet = 0.0, prec = 0.0;
      for (int i = 0; i < B; ++i)
        if (use_[h][static_cast<std::size_t>(i)] && !std::isnan(y[i])) {
          logdet += log_sig2_[static_cast<std::size_t>(i)];
          prec += std::exp(-log_sig2_[static_cast<std::size_t>(i)]);
        }
      // TDOA Gaussian NLL of the LOS set plus a uniform 1/W per discarded (NLOS) anchor.
      metric_[h] =
          0.5 * (f.cost + (nl - 1) * log2pi + logdet + std::log(prec)) + (B - mask_count(hyp_[h])) * logW;
      any = true;
    }
    if (!any) {
      res_.valid = false;
      return res_;
    }
    // Viterbi recursion (Urruela, Morata and Riba 2005): add the best predecessor's metric plus the
    // transition cost -log P(h | h') = sum over anchors of the per-anchor -log p(s_t | s_t-1).
    if (first_) {
      const double c_los = -std::log1p(-opt_.p_nlos), c_nlos = -std::log(opt_.p_nlos);
      for (std::size_t h = 0; h < H; ++h) {
        const int l = mask_count(hyp_[h]);
        delta_[h] = metric_[h] + l * c_los + (B - l) * c_nlos;
      }
    } else {
      prev_ = delta_;
      for (std::size_t h = 0; h < H; ++h) {
        if (!std::isfinite(metric_[h])) {
          delta_[h] = kInf;
          continue;
        }
        double best = kInf;
        const AnchorMask to = hyp_[h];
        for (std::size_t g = 0; g < H; ++g) {
          if (!std::isfinite(prev_[g])) continue;
          const AnchorMask from = hyp_[g];
          const double c = prev_[g] + mask_count(from & to) * c_ll_ + mask_count(from & ~to & all_) * c_ln_ +
                           mask_count(~from & to & all_) * c_nl_ + mask_count(~from & ~to & all_) * c_nn_;
          best = std::min(best, c);
        }
        delta_[h] = metric_[h] + best;
      }
    }
    // Normalise (minimum 0) and decide.
    std::size_t arg = 0;
    double dmin = kInf;
    for (std::size_t h = 0; h < H; ++h)
      if (delta_[h] < dmin) {
        dmin = delta_[h];
        arg = h;
      }
    if (!std::isfinite(dmin)) {  // every path died (e.g. a run of missing rows): restart the trellis
      first_ = true;
      res_.valid = false;
      return res_;
    }
    for (double& d : delta_) d -= dmin;
    res_.theta = fixes_[arg].theta;
    res_.cost = metric_[arg];
    res_.valid = true;
    for (int b = 0; b < B; ++b) res_.sight[b] = ((hyp_[arg] >> b) & 1U) ? 0 : 1;
    first_ = false;
    return res_;
  }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  LosSolver solver_;
  UrruelaOptions opt_;
  std::vector<AnchorMask> hyp_;
  std::vector<Theta> start_;
  std::vector<Fix> fixes_;
  std::vector<double> metric_, delta_, prev_, log_sig2_;
  std::vector<std::vector<char>> use_;
  double c_ll_ = 0, c_ln_ = 0, c_nl_ = 0, c_nn_ = 0;
  AnchorMask all_ = 0;
  SnapshotResult res_;
  bool first_ = true;
};

}  // namespace nlosloc::snapshot
