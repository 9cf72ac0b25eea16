#pragma once
/// \file batch.hpp
/// The batch `run` methods of the Python filters: every row is checked before the first step (a bad row
/// must not leave the filter half-way), and an error names the step it belongs to.
#include <pybind11/pybind11.h>

#include <stdexcept>
#include <string>

#include "nlosloc/core/ensure.hpp"
#include "nlosloc/core/types.hpp"

namespace nlosloc::bind {

/// Calls check(k) for k = 0..T-1 before anything runs; a std::invalid_argument of row k is re-thrown
/// with "step k: " in front (the message of a single step names the argument and the entry).
template <class Check>
void check_steps(Eigen::Index T, Check&& check) {
  for (Eigen::Index k = 0; k < T; ++k) {
    try {
      check(k);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("step " + std::to_string(k) + ": " + e.what());
    }
  }
}

/// Calls step(k) for k = 0..T-1. A NumericalError at step k is re-thrown naming k: each step is atomic,
/// so the filter holds the result of step k-1 (set_belief or reset to go back further).
template <class Step>
void run_steps(Eigen::Index T, Step&& step) {
  for (Eigen::Index k = 0; k < T; ++k) {
    try {
      step(k);
    } catch (const NumericalError& e) {
      throw NumericalError("step " + std::to_string(k) + " (the filter holds step " + std::to_string(k - 1) +
                           "): " + e.what());
    }
  }
}

}  // namespace nlosloc::bind
