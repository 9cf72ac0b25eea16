#pragma once
/// \file result.hpp
/// What a snapshot (per-epoch) baseline returns for one epoch, shared by MleLos, Chen, Cong and Urruela.
#include "nlosloc/core/types.hpp"
#include "nlosloc/snapshot/gauss_newton.hpp"

namespace nlosloc::snapshot {

/// Output of one epoch of a snapshot baseline.
struct SnapshotResult {
  Theta theta;         ///< position (D) then clock bias (RTOA stacks)
  bool valid = false;  ///< false when no fix could be computed this epoch (e.g. every row missing)
  double cost = 0.0;   ///< the cost (or metric) of the selected fix, method-specific
  /// Per-anchor sight decision (0 LOS, 1 NLOS) for the methods that make one (CONG, URR); else all 0.
  VecXi sight;
  /// Number of fixes (Gauss-Newton solves) computed this epoch.
  int fixes = 0;
};

}  // namespace nlosloc::snapshot
