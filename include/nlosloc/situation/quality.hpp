#pragma once
/// \file quality.hpp
/// Quality-statistic likelihoods p(o | s) (Huerta Sec. IV-C, Fig. 6; Grisales p(zeta | z), eq. 36): one
/// noise::Distribution per sight condition, any family of the noise library including the empirical
/// (kernel density) one fitted to a measurement campaign. A missing statistic (NaN) carries no information:
/// its log-likelihood is 0 for every condition.
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "nlosloc/core/random.hpp"
#include "nlosloc/core/types.hpp"
#include "nlosloc/models/noise.hpp"

namespace nlosloc::situation {

/// Throws unless the quality statistics `o` have B entries, each finite or NaN (missing); an infinite
/// statistic is an input error, not an observation (it would have zero density under every condition).
inline void check_statistics(const Eigen::Ref<const VecX>& o, Eigen::Index B) {
  nlosloc::detail::ensure_finite_or_missing(o, B, "o", "finite statistics, or NaN for a missing one",
                                            "anchor");
}

/// Throws unless every anchor's statistic has non-zero density under some condition (each row of the
/// log-likelihood table L (B x N_z) has a finite maximum): an impossible statistic is an input error.
inline void check_support(const MatX& L) {
  for (Eigen::Index b = 0; b < L.rows(); ++b)
    if (!(L.row(b).maxCoeff() > -std::numeric_limits<double>::infinity()))
      nlosloc::detail::throw_invalid_argument("o: statistic of anchor " + std::to_string(b) +
                                              " has zero density under every condition");
}

/// p(o | s = z) for z = 0..N_z-1, the same for every anchor.
class QualityModel {
 public:
  using Dist = noise::Distribution;

  /// `per_condition`: one distribution per condition (N_z >= 1), LOS first.
  explicit QualityModel(std::vector<Dist> per_condition) : d_(std::move(per_condition)) {
    NLOSLOC_ENSURE(!d_.empty(), "per_condition: expected one distribution per sight condition (N_z >= 1)");
  }

  int num_conditions() const { return static_cast<int>(d_.size()); }
  const Dist& distribution(int z) const {
    NLOSLOC_ENSURE(z >= 0 && z < num_conditions(),
                   "z: expected a condition in [0, N_z), got " + std::to_string(z));
    return d_[static_cast<std::size_t>(z)];
  }

  /// log p(o | s = z); 0 when o is NaN (missing); -inf outside the support.
  double log_likelihood(double o, int z) const {
    if (std::isnan(o)) return 0.0;
    return distribution(z).log_pdf(o);
  }
  /// log p(o | s = z) for every z into `out` (size N_z).
  void log_likelihoods(double o, Eigen::Ref<VecX> out) const {
    nlosloc::detail::ensure_shape(out, num_conditions(), 1, "out");
    for (int z = 0; z < num_conditions(); ++z)
      out(z) = std::isnan(o) ? 0.0 : d_[static_cast<std::size_t>(z)].log_pdf(o);
  }
  /// B x N_z table L(b, z) = log p(o_b | s_b = z) for the statistics of all anchors (`o`, size B).
  void log_likelihood_table(const Eigen::Ref<const VecX>& o, MatX& out) const {
    const int nz = num_conditions();
    if (out.rows() != o.size() || out.cols() != nz) out.resize(o.size(), nz);
    for (Eigen::Index b = 0; b < o.size(); ++b)
      for (int z = 0; z < nz; ++z)
        out(b, z) = std::isnan(o(b)) ? 0.0 : d_[static_cast<std::size_t>(z)].log_pdf(o(b));
  }
  /// log_likelihood_table after the checks every filter applies to `o` (B statistics, each finite or NaN;
  /// each possible under some condition): std::invalid_argument naming `o` otherwise.
  void checked_table(const Eigen::Ref<const VecX>& o, Eigen::Index B, MatX& out) const {
    check_statistics(o, B);
    log_likelihood_table(o, out);
    check_support(out);
  }
  /// log p(o | s) = sum_b log p(o_b | s_b) (anchors independent given s).
  double log_likelihood(const Eigen::Ref<const VecX>& o, const Eigen::Ref<const VecXi>& s) const {
    NLOSLOC_ENSURE(o.size() == s.size(), "o, s: expected the same number of anchors");
    check_situation(s);
    double l = 0.0;
    for (Eigen::Index b = 0; b < o.size(); ++b) l += log_likelihood(o(b), s(b));
    return l;
  }
  /// Draws a statistic under condition z (simulation).
  double sample(int z, Rng& rng) const { return distribution(z).sample(rng); }
  /// Draws one statistic per anchor for the situation vector s.
  VecX sample(const Eigen::Ref<const VecXi>& s, Rng& rng) const {
    check_situation(s);
    VecX o(s.size());
    for (Eigen::Index b = 0; b < s.size(); ++b) o(b) = sample(s(b), rng);
    return o;
  }

 private:
  /// Every s_b in [0, N_z), named by the argument and anchor (distribution() would name its own z).
  void check_situation(const Eigen::Ref<const VecXi>& s) const {
    for (Eigen::Index b = 0; b < s.size(); ++b)
      NLOSLOC_ENSURE(s(b) >= 0 && s(b) < num_conditions(),
                     "s: expected conditions in [0, N_z = " + std::to_string(num_conditions()) + "), got " +
                         std::to_string(s(b)) + " at anchor " + std::to_string(b));
  }

  std::vector<Dist> d_;
};

/// Throws the std::invalid_argument a filter's step(y, o) throws for bad inputs: y (meas.rows(), finite or
/// NaN) and o (QualityModel::checked_table, into `table`, the step's own buffer: no allocation once sized).
template <class Meas>
void check_step_inputs(const Meas& meas, const QualityModel& quality, const Eigen::Ref<const VecX>& y,
                       const Eigen::Ref<const VecX>& o, MatX& table) {
  nlosloc::detail::check_measurement(y, meas.rows());
  quality.checked_table(o, meas.num_anchors(), table);
}
/// The same into a table of its own (allocates): for checking ahead, changing nothing.
template <class Meas>
void check_step_inputs(const Meas& meas, const QualityModel& quality, const Eigen::Ref<const VecX>& y,
                       const Eigen::Ref<const VecX>& o) {
  MatX table;
  check_step_inputs(meas, quality, y, o, table);
}

}  // namespace nlosloc::situation
