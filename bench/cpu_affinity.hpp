#pragma once
// CPU affinity for the bench binaries that place threads on given CPUs (nlosloc-micro's BM_RbpfPaired,
// nlosloc-rbpf-phases --pin). Linux only; elsewhere every call fails.
#include <cerrno>
#include <initializer_list>

#if defined(__linux__)
#include <sched.h>
#endif

namespace nlosloc::bench {

/// Restricts the calling thread to `cpus` (threads it starts afterwards inherit the set); false when the
/// system refuses (a CPU that does not exist or is not allowed; errno says why) or has no
/// sched_setaffinity (errno = ENOSYS).
inline bool run_on_cpus(std::initializer_list<int> cpus) {
#if defined(__linux__)
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int c : cpus) {
    if (c < 0 || c >= CPU_SETSIZE) return false;
    CPU_SET(c, &set);
  }
  return sched_setaffinity(0, sizeof set, &set) == 0;
#else
  (void)cpus;
  errno = ENOSYS;
  return false;
#endif
}

}  // namespace nlosloc::bench
