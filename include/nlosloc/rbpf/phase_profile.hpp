#pragma once
/// \file phase_profile.hpp
/// Opt-in timeline of the reordered RBPF step (Rbpf::reordered_region's phases A-E), to see where the
/// second core's time goes (bench/phases/rbpf_phases.cpp prints it for the H2 model). Compiled in only
/// when NLOSLOC_RBPF_PHASE_PROFILE is defined in every translation unit of the program (a program that
/// defines it in some only breaks the one-definition rule); otherwise mark() and begin_step() are empty
/// inline functions and the filters carry no cost.
///
/// Each thread of the step's parallel region records, at the end of each phase it runs, the time since the
/// step began (begin_step on the calling thread), summed over steps in process-wide slots: profile one
/// filter at a time, and read the sums (snapshot) only between steps.
#include <array>
#include <chrono>

namespace nlosloc::rbpf::phase_profile {

#ifdef NLOSLOC_RBPF_PHASE_PROFILE
inline constexpr bool kEnabled = true;
#else
inline constexpr bool kEnabled = false;
#endif

/// Phases of the reordered step in the order a thread runs them (a thread records only those it runs).
enum Phase : int {
  kRegionStart = 0,  ///< the thread entered the step's parallel region (hand-off)
  kSweepSetup,       ///< thread 0: prepare_sweep (predicted means bucketed for the neighbour sweep)
  kFactors,          ///< the thread's chunks of the parents' factors, best and known child weights
  kSweep,            ///< its chunks of the neighbour sweep (eq. 29)
  kWaitFactors,      ///< barrier: every factor and sweep chunk done
  kSort,             ///< the thread's parents by decreasing best child
  kNearChildren,     ///< children of parents with a neighbour; first shared bound
  kWaitBound,        ///< barrier: every first bound published
  kEnumeration,      ///< children that can reach the shared cut (enumerate_share)
  kWaitMerge,        ///< barrier: every near parent's children written
  kMerge,            ///< merge of the thread's key range (eqs. 29-30)
  kTrim,             ///< candidates below the final shared bound dropped (finish_candidates)
  kWaitSelection,    ///< barrier: every candidate list final
  kSelection,        ///< thread 0: the M heaviest, ordered and split for the bank (select_kept)
  kSpeculation,  ///< the other threads meanwhile: UKF updates of their likeliest kept children (speculate)
  kWaitBank,     ///< the selection published
  kBank,         ///< the thread's chunks of the UKF bank (eq. 26, Table III), each with its moments of
                 ///< eqs. (27)-(28) and next predicted means
  kJoin,         ///< thread 0: every thread left the region
  kStepEnd,      ///< thread 0: the step returns (normalisation, eq. 28, swaps)
  kPhaseCount
};

/// Short name of a phase, for tables.
inline const char* name(Phase p) {
  static constexpr std::array<const char*, kPhaseCount> kNames = {
      "region start", "sweep set-up",  "factors",       "sweep",       "wait (sweeps)",
      "sort",         "near children", "wait (bound)",  "enumeration", "wait (merge)",
      "merge",        "trim",          "wait (select)", "selection",   "speculation",
      "wait (bank)",  "UKF bank",      "join",          "step end"};
  return p >= 0 && p < kPhaseCount ? kNames[static_cast<std::size_t>(p)] : "?";
}

/// Threads with a slot (a region's threads beyond it are not recorded).
inline constexpr int kMaxThreads = 8;

/// One thread's sums over the recorded steps: per phase, the summed end time (microseconds from the step's
/// start) and how many steps recorded it. A line of its own: the threads write theirs concurrently.
struct alignas(64) ThreadSums {
  std::array<double, kPhaseCount> end_us{};
  std::array<long, kPhaseCount> hits{};
};

/// The recorded steps and each thread's sums.
struct Totals {
  long steps = 0;
  std::array<ThreadSums, kMaxThreads> threads{};
};

namespace detail {
using Clock = std::chrono::steady_clock;
inline Totals totals;
inline Clock::time_point step_start;
}  // namespace detail

/// Starts a step's timeline (the filter's calling thread, before its region).
inline void begin_step() {
  if constexpr (kEnabled) {
    detail::step_start = detail::Clock::now();
    ++detail::totals.steps;
  }
}

/// Records that `thread` (0 = the calling thread) finished phase p of the current step.
inline void mark(int thread, Phase p) {
  if constexpr (kEnabled) {
    if (thread < 0 || thread >= kMaxThreads) return;
    const double us =
        std::chrono::duration<double, std::micro>(detail::Clock::now() - detail::step_start).count();
    auto& s = detail::totals.threads[static_cast<std::size_t>(thread)];
    s.end_us[static_cast<std::size_t>(p)] += us;
    ++s.hits[static_cast<std::size_t>(p)];
  } else {
    (void)thread;
    (void)p;
  }
}

/// Clears the sums (between steps).
inline void reset() { detail::totals = Totals{}; }

/// The sums so far (between steps).
inline Totals snapshot() { return detail::totals; }

}  // namespace nlosloc::rbpf::phase_profile
