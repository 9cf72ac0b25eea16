// nlosloc-rbpf-phases: timeline of the reordered RBPF step on the H2 model (bench/h2_micro_model.hpp), on
// 1 thread and on more, to see where the second core's time goes (issue #3: 2-core speed-up >= 1.8).
// Built with NLOSLOC_RBPF_PHASE_PROFILE (include/nlosloc/rbpf/phase_profile.hpp); the marks cost a clock
// read each (about 20 per thread and step), so the step times here run a little above nlosloc-micro's
// BM_Rbpf, which is the speed measurement.
//
//     nlosloc-rbpf-phases [--particles 128] [--threads 1,2] [--steps 20000] [--augmented] [--pin 0,1]
//
// --pin A,B runs the calling thread (thread 0) on CPU A and the pool's workers on CPU B (Linux): with
// B,A against A,B it tells a slow CPU (the slow thread follows the CPU) from a slow share of the work
// (it stays with the thread).
//
// For each thread count: per phase and thread, the mean time from the step's start to the phase's end and
// the phase's mean duration; then the UKF bank (bank + moments, slowest thread) and the rest of the step
// against the 1-thread run. Exit code 2 on a bad argument, 1 when a thread's phase ends are out of order.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../cli_decimal.hpp"
#include "../cpu_affinity.hpp"
#include "../h2_micro_model.hpp"
#include "nlosloc/rbpf/phase_profile.hpp"
#include "nlosloc/rbpf/rbpf.hpp"

#ifndef NLOSLOC_RBPF_PHASE_PROFILE
#error "bench/phases/rbpf_phases.cpp needs NLOSLOC_RBPF_PHASE_PROFILE (its CMake target defines it)"
#endif

namespace {
using namespace nlosloc;
namespace pp = nlosloc::rbpf::phase_profile;

/// Mean phase end times of one run (us from the step's start; < 0: the thread never ran the phase).
struct Timeline {
  int threads = 1;
  long steps = 0;
  std::vector<std::vector<double>> end;    // [thread][phase]
  std::vector<std::vector<double>> share;  // [thread][phase]: fraction of the steps that recorded it
};

/// Adds the sums of `more` to `sum`.
void add(pp::Totals& sum, const pp::Totals& more) {
  sum.steps += more.steps;
  for (std::size_t t = 0; t < sum.threads.size(); ++t)
    for (std::size_t p = 0; p < pp::kPhaseCount; ++p) {
      sum.threads[t].end_us[p] += more.threads[t].end_us[p];
      sum.threads[t].hits[p] += more.threads[t].hits[p];
    }
}

/// Restricts the calling thread to `cpu` (threads it creates inherit it); false and a message on failure.
bool pin_to(int cpu) {
  if (bench::run_on_cpus({cpu})) return true;
  std::fprintf(stderr, "error: --pin: cannot run on CPU %d: %s\n", cpu, std::strerror(errno));
  return false;
}

/// Runs `steps` timed steps (cycling the 1024-step track; the filter restarts at each cycle and its 50
/// first steps, with few particles, are left out of the sums) and returns the mean timeline.
/// pin: {caller CPU, worker CPU}, or empty.
Timeline run(int threads, int particles, bool augmented, long steps, const std::vector<int>& pin) {
  const bench::H2Model& h = bench::model();
  rbpf::RbpfOptions opt;
  opt.variant = rbpf::RbpfVariant::kReordered;
  opt.num_particles = particles;
  opt.threads = threads;
  opt.noise_form = augmented ? NoiseForm::kAugmented : NoiseForm::kAdditive;
  // The filter's pool starts its workers in the constructor: they inherit the worker CPU.
  if (!pin.empty() && !pin_to(pin[1])) std::exit(2);
  rbpf::Rbpf<ConstantVelocityClock2> f(h.motion, h.st, h.proc, h.q, h.init, opt);
  if (!pin.empty() && !pin_to(pin[0])) std::exit(2);
  constexpr std::size_t kWarm = 50;
  pp::Totals tot;
  for (long done = 0; done < steps;) {
    f.reset(h.init);
    std::size_t k = 0;
    for (; k < kWarm; ++k) f.step(h.y[k], h.o[k]);
    pp::reset();
    for (; k < h.y.size() && done < steps; ++k, ++done) f.step(h.y[k], h.o[k]);
    add(tot, pp::snapshot());
  }
  Timeline tl;
  tl.threads = threads;
  tl.steps = tot.steps;
  const int shown = std::min(threads, pp::kMaxThreads);
  tl.end.assign(static_cast<std::size_t>(shown), std::vector<double>(pp::kPhaseCount, -1.0));
  tl.share.assign(static_cast<std::size_t>(shown), std::vector<double>(pp::kPhaseCount, 0.0));
  for (std::size_t t = 0; t < static_cast<std::size_t>(shown); ++t)
    for (std::size_t p = 0; p < pp::kPhaseCount; ++p)
      if (const long hits = tot.threads[t].hits[p]; hits > 0) {
        tl.end[t][p] = tot.threads[t].end_us[p] / static_cast<double>(hits);
        tl.share[t][p] = static_cast<double>(hits) / static_cast<double>(tot.steps);
      }
  return tl;
}

/// Mean duration of phase p on thread t: its end minus the end of the thread's previous recorded phase
/// (the step's start for the first).
double duration(const Timeline& tl, std::size_t t, std::size_t p) {
  double prev = 0.0;
  for (std::size_t q = 0; q < p; ++q)
    if (tl.end[t][q] >= 0.0) prev = tl.end[t][q];
  return tl.end[t][p] - prev;
}

/// Slowest thread's bank + moments time (us).
double bank_time(const Timeline& tl) {
  double worst = 0.0;
  for (std::size_t t = 0; t < tl.end.size(); ++t)
    if (tl.end[t][pp::kBank] >= 0.0 && tl.end[t][pp::kWaitBank] >= 0.0)
      worst = std::max(worst, tl.end[t][pp::kBank] - tl.end[t][pp::kWaitBank]);
  return worst;
}

/// False (and a message) when a thread's mean phase ends decrease in phase order (they cannot in any step).
bool check_order(const Timeline& tl) {
  bool ok = true;
  for (std::size_t t = 0; t < tl.end.size(); ++t) {
    double last = 0.0;
    for (std::size_t p = 0; p < pp::kPhaseCount; ++p) {
      if (tl.end[t][p] < 0.0) continue;
      if (tl.end[t][p] < last - 1e-9) {
        std::fprintf(stderr,
                     "error: %d threads, thread %zu: '%s' ends before an earlier phase (%.3f < %.3f us)\n",
                     tl.threads, t, pp::name(static_cast<pp::Phase>(p)), tl.end[t][p], last);
        ok = false;
      }
      last = std::max(last, tl.end[t][p]);
    }
  }
  return ok;
}

void print(const Timeline& tl) {
  std::printf("\n%d thread%s, %ld steps: mean end (us from the step's start) / duration of each phase\n",
              tl.threads, tl.threads == 1 ? "" : "s", tl.steps);
  std::printf("%-15s", "phase");
  for (std::size_t t = 0; t < tl.end.size(); ++t) std::printf("   thread %zu end / dur ", t);
  std::printf("\n");
  for (std::size_t p = 0; p < pp::kPhaseCount; ++p) {
    bool any = false;
    for (std::size_t t = 0; t < tl.end.size(); ++t) any = any || tl.end[t][p] >= 0.0;
    if (!any) continue;
    std::printf("%-15s", pp::name(static_cast<pp::Phase>(p)));
    for (std::size_t t = 0; t < tl.end.size(); ++t) {
      if (tl.end[t][p] < 0.0) {
        std::printf("   %20s", "-");
        continue;
      }
      std::printf("   %8.2f / %7.2f", tl.end[t][p], duration(tl, t, p));
      std::printf(tl.share[t][p] < 1.0 ? "*" : " ");
    }
    std::printf("\n");
  }
  std::printf("(* recorded in only some steps: its mean is over those)\n");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nlosloc-rbpf-phases: timeline of the reordered RBPF step on the H2 model"};
  int particles = 128;
  std::vector<int> threads{1, 2};
  long steps = 20000;
  bool augmented = false;
  std::vector<int> pin;
  const auto dec = nlosloc::bench::decimal(1ULL << 40);  // CLI11 alone reads "010" as 8
  app.add_option("--particles,-M", particles, "M, particles kept per step (default 128)")
      ->transform(dec)
      ->check(CLI::Range(1, 1 << 20));
  app.add_option("--threads", threads, "Thread counts, the first the reference (default 1,2)")
      ->delimiter(',')
      ->transform(dec)
      ->check(CLI::Range(1, 256));
  app.add_option("--steps", steps, "Timed steps per thread count (default 20000)")
      ->transform(dec)
      ->check(CLI::Range(1L, 1L << 40));
  app.add_flag("--augmented", augmented, "Augmented-noise UKF bank (Table III) instead of the additive one");
  app.add_option("--pin", pin, "CPU of the calling thread and CPU of the workers, e.g. 0,1 (Linux)")
      ->delimiter(',')
      ->expected(2)
      ->transform(dec)
      ->check(CLI::Range(0, 1023));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == static_cast<int>(CLI::ExitCodes::Success) ? 0 : 2;
  }
  std::printf("rRBPF-%d, %s UKF bank, H2 model", particles, augmented ? "augmented" : "additive");
  if (!pin.empty()) std::printf(", thread 0 on CPU %d, workers on CPU %d", pin[0], pin[1]);
  std::printf("\n");
  bool ok = true;
  std::vector<Timeline> runs;
  for (const int T : threads) {
    runs.push_back(run(T, particles, augmented, steps, pin));
    print(runs.back());
    ok = check_order(runs.back()) && ok;
  }
  const Timeline& ref = runs.front();
  const double ref_step = ref.end[0][pp::kStepEnd], ref_bank = bank_time(ref);
  std::printf("\n%-9s %12s %9s %14s %9s %16s %9s\n", "threads", "step (us)", "speed-up", "bank+mom (us)",
              "speed-up", "rest of step (us)", "speed-up");
  for (const Timeline& tl : runs) {
    const double step = tl.end[0][pp::kStepEnd], bank = bank_time(tl);
    std::printf("%-9d %12.2f %9.3f %14.2f %9.3f %16.2f %9.3f\n", tl.threads, step, ref_step / step, bank,
                ref_bank / bank, step - bank, (ref_step - ref_bank) / (step - bank));
  }
  return ok ? 0 : 1;
}
