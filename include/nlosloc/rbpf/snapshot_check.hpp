#pragma once
/// \file snapshot_check.hpp
/// Checks shared by Rbpf::restore and ParticleFilter::restore: the fields both snapshots hold, with the same
/// messages.
#include <cmath>
#include <string>

#include "nlosloc/core/ensure.hpp"
#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/core/types.hpp"

namespace nlosloc::rbpf::detail {

/// Throws unless `lw` (snapshot.log_weights, shape already checked) holds log weights, finite or -inf,
/// whose log-sum-exp is 0 within 1e-9.
inline void check_snapshot_log_weights(const VecX& lw) {
  NLOSLOC_ENSURE(are_log_weights(lw), "snapshot.log_weights: expected finite values or -inf");
  const double total = log_sum_exp(lw);
  NLOSLOC_ENSURE(std::abs(total) <= 1e-9,
                 "snapshot.log_weights: expected normalised log weights (log-sum-exp 0), got log-sum-exp " +
                     std::to_string(total));
}

/// Throws unless snapshot.time is finite and snapshot.step >= 0.
inline void check_snapshot_clock(double time, long step) {
  NLOSLOC_ENSURE(std::isfinite(time), "snapshot.time: expected a finite time (s)");
  NLOSLOC_ENSURE(step >= 0, "snapshot.step: expected >= 0, got " + std::to_string(step));
}

}  // namespace nlosloc::rbpf::detail
