#pragma once
/// \file mle_los.hpp
/// MLE-LOS of Huerta et al. 2009 Sec. VI-A: the maximum-likelihood position (and clock bias for RTOA) from
/// the observations of the current epoch only, every anchor assumed LOS (Gaussian LOS noise of each row,
/// condition 0 of the stack). Solved by damped Gauss-Newton (gauss_newton.hpp) from the best of up to three
/// starts: the closed-form linear LS of the TOA/RTOA rows, the polar inversion of a TOA + AOA pair of one
/// anchor (H1: range and bearing fix the position exactly), and the previous epoch's fix (a numerical warm
/// start only; the estimate uses no prior information).
#include <cmath>
#include <limits>
#include <vector>

#include "nlosloc/snapshot/gauss_newton.hpp"
#include "nlosloc/snapshot/result.hpp"

namespace nlosloc::snapshot {

/// Per-epoch LOS maximum-likelihood fix (MLE-LOS).
class MleLos {
 public:
  explicit MleLos(const MeasurementStack& stack, const GaussNewtonOptions& opt = {}) : solver_(stack, opt) {
    last_.setZero(solver_.unknowns());
    res_.theta = last_;
    res_.sight.setZero(stack.num_anchors());
    use_.assign(static_cast<std::size_t>(stack.rows()), 1);
  }

  const LosSolver& solver() const { return solver_; }
  /// Its only options: the Gauss-Newton settings of the solver.
  const GaussNewtonOptions& options() const { return solver_.options(); }
  /// MLE-LOS does not classify sight (sight() is all LOS).
  bool classifies_sight() const { return false; }
  const VecXi& sight() const { return res_.sight; }

  /// Sets the warm start (position, then clock bias when the stack has RTOA rows).
  void reset(const Theta& start) {
    detail::ensure_shape(start, solver_.unknowns(), 1, "start");
    detail::ensure_finite(start, "start");
    last_ = start;
  }

  /// The fix of epoch y (NaN rows skipped). When no fix is possible (fewer observed rows than unknowns:
  /// an underdetermined epoch has no unique fix, as CHEN, CONG and URR also say) the previous one is
  /// returned with valid = false.
  const SnapshotResult& solve(const Eigen::Ref<const VecX>& y) {
    detail::check_measurement(y, solver_.stack().rows());  // polar_start reads y before any solve
    res_.fixes = 0;
    res_.valid = false;
    Fix best;
    auto consider = [&](const Theta& start) {
      const Fix f = solver_.solve(y, start, use_, solver_.los_noise());
      ++res_.fixes;
      if (f.rows > 0 && std::isfinite(f.cost) && f.theta.allFinite() &&
          (!best.theta.size() || f.cost < best.cost))
        best = f;
    };
    Theta s;
    if (solver_.linear_start(y, use_, s)) consider(s);
    if (polar_start(y, s)) consider(s);
    consider(last_);
    if (best.theta.size() && best.rows >= solver_.unknowns()) {
      last_ = best.theta;
      res_.valid = true;
      res_.cost = best.cost;
    }
    res_.theta = last_;
    return res_;
  }

 private:
  /// Position from the first TOA row and an AOA / AOA-phase row of the same anchor:
  /// p = q + r (cos theta, sin theta), theta the bearing (phase psi = pi sin(theta - c) inverted on the
  /// broadside half-plane of the serving array, theta = c + asin(psi / pi)). 2-D only.
  bool polar_start(const Eigen::Ref<const VecX>& y, Theta& theta) const {
    const MeasurementStack& st = solver_.stack();
    if (st.layout().space_dim != 2 || solver_.has_clock()) return false;
    for (int i = 0; i < st.rows(); ++i) {
      if (st.row(i).kind != RowKind::kToa || std::isnan(y[i])) continue;
      for (int j = 0; j < st.rows(); ++j) {
        const MeasurementRow& a = st.row(j);
        if (a.anchor != st.row(i).anchor || std::isnan(y[j])) continue;
        double bearing;
        if (a.kind == RowKind::kAoa) {
          bearing = y[j];
        } else if (a.kind == RowKind::kAoaPhase) {
          const double s = std::max(-1.0, std::min(1.0, y[j] / kPi));
          bearing = a.sector_center + std::asin(s);
        } else {
          continue;
        }
        const double r = std::max(0.0, y[i] - solver_.los_noise()[static_cast<std::size_t>(i)].center);
        theta.resize(2);
        theta[0] = st.anchors()(a.anchor, 0) + r * std::cos(bearing);
        theta[1] = st.anchors()(a.anchor, 1) + r * std::sin(bearing);
        return true;
      }
    }
    return false;
  }

  LosSolver solver_;
  Theta last_;
  SnapshotResult res_;
  std::vector<char> use_;
};

}  // namespace nlosloc::snapshot
