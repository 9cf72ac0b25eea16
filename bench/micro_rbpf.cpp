// Micro-benchmarks of the RBPF family on an H2-like model (Huerta Sec. VI-B: 6 anchors on a hexagon of
// 3 km, RTOA, 6-state [p, tau, v, tau_dot], LOS Normal var 10 / NLOS Rayleigh var 5000, speed-dependent
// sight chain with E{L} = 10 m, Beta quality statistics). Time per step of rRBPF-16, rRBPF-128, cRBPF-128
// (M = 2, 128 UKF runs) and the joint PF (items = particles, so ns per particle per step), on 1 and 2
// threads. Targets of issue #3: rRBPF-128 <= 1 ms per step on one core, 2-core speed-up >= 1.8, PF <= 50 ns
// per particle per step.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <vector>

#include "cpu_affinity.hpp"
#include "h2_micro_model.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/rbpf/pf.hpp"
#include "nlosloc/rbpf/rbpf.hpp"
#include "nlosloc/rbpf/thread_pool.hpp"

namespace {
using namespace nlosloc;
using nlosloc::bench::H2Model;
using nlosloc::bench::model;

/// args: variant (0 classical, 1 reordered), M, threads[, noise form (0 additive, 1 augmented: Table III)]
void BM_Rbpf(benchmark::State& state) {
  const H2Model& h = model();
  rbpf::RbpfOptions opt;
  opt.variant = state.range(0) == 0 ? rbpf::RbpfVariant::kClassical : rbpf::RbpfVariant::kReordered;
  opt.num_particles = static_cast<int>(state.range(1));
  opt.threads = static_cast<int>(state.range(2));
  opt.noise_form = state.range(3) == 1 ? NoiseForm::kAugmented : NoiseForm::kAdditive;
  rbpf::Rbpf<ConstantVelocityClock2> f(h.motion, h.st, h.proc, h.q, h.init, opt);
  std::size_t k = 0;
  for (int w = 0; w < 50; ++w, ++k) f.step(h.y[k], h.o[k]);  // past the first (single-particle) steps
  for (auto _ : state) {
    const auto info = f.step(h.y[k & 1023], h.o[k & 1023]);
    benchmark::DoNotOptimize(info.log_likelihood);
    if ((++k & 1023) == 0) {
      state.PauseTiming();
      f.reset(h.init);
      state.ResumeTiming();
    }
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}
// rRBPF-16, rRBPF-128, cRBPF-128 (M = 2 propagated, 2 x 64 = 128 UKF runs), each on 1 and 2 threads
// and rRBPF-128 / cRBPF-128 with the augmented (Table III) noise form
BENCHMARK(BM_Rbpf)
    ->ArgNames({"reordered", "M", "threads", "augmented"})
    ->Args({1, 16, 1, 0})
    ->Args({1, 16, 2, 0})
    ->Args({1, 128, 1, 0})
    ->Args({1, 128, 2, 0})
    ->Args({0, 2, 1, 0})
    ->Args({0, 2, 2, 0})
    ->Args({1, 128, 1, 1})
    ->Args({1, 128, 2, 1})
    ->Args({0, 2, 1, 1})
    ->Args({0, 2, 2, 1})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

#if defined(__linux__)
/// Runs the calling thread on `cpu` only, or (cpu < 0) on CPUs 0 and 1; false on failure.
bool run_on(int cpu) { return cpu >= 0 ? bench::run_on_cpus({cpu}) : bench::run_on_cpus({0, 1}); }

/// Times three steppers in lockstep: j = 0 and 1 run on one thread, on CPU 0 and CPU 1; j = 2 on two
/// threads, its calling thread on CPU 0 (its worker must have been created on CPU 1). Each runs a block of
/// `block` steps in turn, the order rotating, each block timed; restart(j) (untimed) starts stepper j
/// again and returns its first step index, called whenever the next block would pass `length`;
/// run_block(j, k, block) runs steps k to k + block - 1 of stepper j and returns their time (us; for
/// stepper 2, the time one thread would take at its rate, when that is not its wall time). Counters: mean
/// step of each (us) and speed-up = mean 1-thread time (of the two CPUs) / stepper 2's time, over all
/// blocks. Returns that mean 1-thread time (us per step).
template <class Restart, class RunBlock>
double time_lockstep_blocks(benchmark::State& state, std::size_t block, std::size_t length, Restart&& restart,
                            RunBlock&& run_block) {
  const int cpu[3] = {0, 1, 0};
  std::size_t k = length;
  double sum[3] = {0.0, 0.0, 0.0};
  long steps = 0, round = 0;
  for (auto _ : state) {
    if (k + block > length)
      for (int j = 0; j < 3; ++j) {
        run_on(cpu[j]);
        k = restart(j);
      }
    for (int turn = 0; turn < 3; ++turn) {
      const int j = static_cast<int>((round + turn) % 3);
      run_on(cpu[j]);
      sum[j] += run_block(j, k, block);
    }
    ++round;
    k += block;
    steps += static_cast<long>(block);
  }
  run_on(-1);
  const double n = static_cast<double>(steps);
  state.counters["t1_cpu0_us"] = sum[0] / n;
  state.counters["t1_cpu1_us"] = sum[1] / n;
  state.counters["t2_us"] = sum[2] / n;
  state.counters["speedup"] = 0.5 * (sum[0] + sum[1]) / sum[2];
  return 0.5 * (sum[0] + sum[1]) / n;
}

/// Wall time (us) of fn().
template <class Fn>
double time_us(Fn&& fn) {
  const auto t0 = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
}

/// time_lockstep_blocks where step(j, i) runs step i of stepper j (stepper 2: one 2-thread step), each
/// block timed on the wall.
template <class Restart, class Step>
void time_lockstep(benchmark::State& state, std::size_t block, std::size_t length, Restart&& restart,
                   Step&& step) {
  time_lockstep_blocks(state, block, length, restart, [&](int j, std::size_t k, std::size_t n) {
    return time_us([&] {
      for (std::size_t i = k; i < k + n; ++i) step(j, i);
    });
  });
}

/// The options of BM_RbpfPaired's and BM_RbpfConcurrent's filters (args: variant, M, noise form), on one
/// thread.
rbpf::RbpfOptions paired_options(const benchmark::State& state) {
  rbpf::RbpfOptions opt;
  opt.variant = state.range(0) == 0 ? rbpf::RbpfVariant::kClassical : rbpf::RbpfVariant::kReordered;
  opt.num_particles = static_cast<int>(state.range(1));
  opt.noise_form = state.range(2) == 1 ? NoiseForm::kAugmented : NoiseForm::kAdditive;
  opt.threads = 1;
  return opt;
}

/// BM_RbpfPaired's and BM_RbpfConcurrent's cases: rRBPF-128 additive and augmented, cRBPF-128 additive,
/// with their steps per block (rbpf_speedup.py's PAIRED_BLOCK).
void paired_cases(benchmark::internal::Benchmark* b) {
  b->ArgNames({"reordered", "M", "augmented", "block"})
      ->Args({1, 128, 0, 64})
      ->Args({1, 128, 1, 16})
      ->Args({0, 2, 0, 64})
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}

/// Restarts filter f on the H2 track and runs it past the first (single-particle) steps, as BM_Rbpf;
/// returns the first step index to time.
std::size_t warm_start(rbpf::Rbpf<ConstantVelocityClock2>& f) {
  constexpr std::size_t kWarm = 50;
  const H2Model& h = model();
  f.reset(h.init);
  for (std::size_t i = 0; i < kWarm; ++i) f.step(h.y[i], h.o[i]);
  return kWarm;
}

/// The 2-thread speed-up measured in lockstep (Linux, 2 CPUs; time_lockstep): two 1-thread filters, one
/// on CPU 0 and one on CPU 1, and a 2-thread filter (args: variant, M, noise form as BM_Rbpf, then steps
/// per block) run the same track. On a shared 2-vCPU host the time per step drifts by 2x within seconds
/// and each vCPU on its own (an arithmetic loop pinned to one ran 85-188 ns per iteration, 2026-12-04),
/// so whole benchmarks seconds apart misstate the ratio, and so does a 1-thread run on whichever vCPU the
/// scheduler picked; blocks a few ms apart on both vCPUs see the same host.
void BM_RbpfPaired(benchmark::State& state) {
  const H2Model& h = model();
  rbpf::RbpfOptions opt = paired_options(state);
  if (!run_on(-1) || !run_on(1) || !run_on(0)) {
    state.SkipWithError("needs CPUs 0 and 1");
    return;
  }
  rbpf::Rbpf<ConstantVelocityClock2> f0(h.motion, h.st, h.proc, h.q, h.init, opt);
  rbpf::Rbpf<ConstantVelocityClock2> f1(h.motion, h.st, h.proc, h.q, h.init, opt);
  // The 2-thread filter's worker starts on CPU 1 and stays there (a thread inherits its creator's CPUs);
  // its calling thread (thread 0) runs on CPU 0. Unpinned, thread 0 began each block on the CPU of the
  // block before (0 or 1 as the order rotates), so the threads' CPUs and caches changed from block to
  // block: 84-86 us per 2-thread step against 77-78 pinned (additive), 276-279 against 241-242
  // (augmented), the 1-thread blocks unchanged (alternate builds, 2026-12-04).
  run_on(1);
  opt.threads = 2;
  rbpf::Rbpf<ConstantVelocityClock2> f2(h.motion, h.st, h.proc, h.q, h.init, opt);
  rbpf::Rbpf<ConstantVelocityClock2>* f[3] = {&f0, &f1, &f2};
  time_lockstep(
      state, static_cast<std::size_t>(state.range(3)), h.y.size(), [&](int j) { return warm_start(*f[j]); },
      [&](int j, std::size_t i) { benchmark::DoNotOptimize(f[j]->step(h.y[i], h.o[i])); });
}
BENCHMARK(BM_RbpfPaired)->Apply(paired_cases);

/// The host's own ceiling for the filter's 2-thread speed-up: what two CPUs give when nothing passes
/// between them. Args as BM_RbpfPaired. Stepper 2 is two independent 1-thread filters stepped at the same
/// time, one on CPU 0 and one on CPU 1 (a 2-thread ThreadPool hands each its whole block: one hand-off and
/// one join per block, no line shared). Each thread times its own block and the pair's rates add, so
/// speed-up = the throughput of both CPUs at once over that of one. Summing rates, not waiting for the
/// slower of the pair, keeps a vCPU's stall from counting against the bound: a filter whose threads share
/// the work at run time can absorb one. On a host whose CPUs slow each other down (SMT siblings, a busy
/// host) it falls below 2 with no filter code. Also counted: speedup_joined (t2_joined_us), the pair timed
/// on the wall to each block's join, as a split into fixed halves with one exchange per block would be.
void BM_RbpfConcurrent(benchmark::State& state) {
  const H2Model& h = model();
  const rbpf::RbpfOptions opt = paired_options(state);
  if (!run_on(-1) || !run_on(1) || !run_on(0)) {
    state.SkipWithError("needs CPUs 0 and 1");
    return;
  }
  rbpf::Rbpf<ConstantVelocityClock2> f0(h.motion, h.st, h.proc, h.q, h.init, opt);
  rbpf::Rbpf<ConstantVelocityClock2> f1(h.motion, h.st, h.proc, h.q, h.init, opt);
  rbpf::Rbpf<ConstantVelocityClock2> g0(h.motion, h.st, h.proc, h.q, h.init, opt);
  rbpf::Rbpf<ConstantVelocityClock2> g1(h.motion, h.st, h.proc, h.q, h.init, opt);
  run_on(1);  // the pool's worker stays on CPU 1 and steps g1; the calling thread steps g0 on CPU 0
  rbpf::ThreadPool pool(2);
  rbpf::Rbpf<ConstantVelocityClock2>* f[2] = {&f0, &f1};
  rbpf::Rbpf<ConstantVelocityClock2>* g[2] = {&g0, &g1};
  double joined_us = 0.0, joined_steps = 0.0;
  const double t1 = time_lockstep_blocks(
      state, static_cast<std::size_t>(state.range(3)), h.y.size(),
      [&](int j) {
        if (j < 2) return warm_start(*f[j]);
        std::size_t k[2] = {0, 0};  // each of the pair warms on the CPU it then runs on
        pool.parallel_for(2, [&](int, int, int th) { k[th] = warm_start(*g[th]); });
        return k[0];
      },
      [&](int j, std::size_t k, std::size_t n) {
        auto run = [&](rbpf::Rbpf<ConstantVelocityClock2>& filter) {
          return time_us([&] {
            for (std::size_t i = k; i < k + n; ++i) benchmark::DoNotOptimize(filter.step(h.y[i], h.o[i]));
          });
        };
        if (j < 2) return run(*f[j]);
        double t[2] = {0.0, 0.0};
        joined_us += time_us([&] { pool.parallel_for(2, [&](int, int, int th) { t[th] = run(*g[th]); }); });
        joined_steps += 2 * static_cast<double>(n);
        return t[0] * t[1] / (t[0] + t[1]);  // the pair's rates add: 1 / (1 / t0 + 1 / t1)
      });
  // The same pair timed on the wall, to the join: the slower of the two sets each block's time
  state.counters["t2_joined_us"] = joined_us / joined_steps;
  state.counters["speedup_joined"] = t1 * joined_steps / joined_us;
}
BENCHMARK(BM_RbpfConcurrent)->Apply(paired_cases);

/// The ceiling of the speed-up above on this host: a synthetic step of about the filter's length (115 us
/// on one thread) whose work divides exactly in two, run as the filter runs its region: one pool hand-off,
/// `phases` phases split by SpinBarrier rounds, the join (phases = 7: eight exchanges between the cores,
/// as a reordered RBPF step that merges). Each phase updates a block of columns of 128 rows of
/// arithmetic (sqrt, log1p: in-cache work as the UKF's), each thread half the rows. cross = 0: each
/// thread keeps its half of the rows, so it only touches lines its own core wrote; cross = 1: the halves
/// swap at every phase, so every line a thread reads was last written by the other core. Any shortfall
/// from 2x here is the host's and the pool's, not the filter's.
class SplitStep {
 public:
  static constexpr int kRows = 128, kCols = 147;  // 147 = 3 x 7 x 7 columns: 1, 3 or 7 phases
  SplitStep(int threads, int phases, bool cross)
      : pool_(threads), threads_(threads), phases_(phases), cross_(cross), x_(kRows * kCols, 0.5) {}
  void step(std::size_t i) {
    const int cols = kCols / phases_;
    pool_.parallel_for(threads_, [&](int, int, int th) {
      for (int p = 0; p < phases_; ++p) {
        const int half = cross_ ? (th + p + static_cast<int>(i & 1)) % threads_ : th;
        for (int r = kRows * half / threads_; r < kRows * (half + 1) / threads_; ++r)
          for (double *v = &x_[static_cast<std::size_t>(r * kCols + p * cols)], *e = v + cols; v < e; ++v)
            *v = 0.5 * (std::sqrt(*v * *v + 1.0) + 0.5 * std::log1p(std::fabs(*v))) + 0.1;
        if (p + 1 < phases_) barrier_.arrive_and_wait(threads_);
      }
    });
    benchmark::DoNotOptimize(x_.data());
  }

 private:
  rbpf::ThreadPool pool_;
  rbpf::SpinBarrier barrier_;
  int threads_, phases_;
  bool cross_;
  std::vector<double> x_;
};

/// args: phases (1, 3 or 7), cross (0 or 1), steps per block. Counters as BM_RbpfPaired.
void BM_SplitCeiling(benchmark::State& state) {
  const auto phases = static_cast<int>(state.range(0));
  const bool cross = state.range(1) == 1;
  if (phases < 1 || SplitStep::kCols % phases != 0) {
    state.SkipWithError("phases: expected a divisor of 147 (1, 3, 7, ...)");
    return;
  }
  if (!run_on(-1) || !run_on(1) || !run_on(0)) {
    state.SkipWithError("needs CPUs 0 and 1");
    return;
  }
  SplitStep s0(1, phases, cross), s1(1, phases, cross);
  run_on(1);  // the 2-thread step's worker on CPU 1, as BM_RbpfPaired's
  SplitStep s2(2, phases, cross);
  SplitStep* s[3] = {&s0, &s1, &s2};
  time_lockstep(
      state, static_cast<std::size_t>(state.range(2)), std::size_t{1} << 20,
      [](int) { return std::size_t{0}; }, [&](int j, std::size_t i) { s[j]->step(i); });
}
BENCHMARK(BM_SplitCeiling)
    ->ArgNames({"phases", "cross", "block"})
    ->Args({1, 0, 64})
    ->Args({3, 0, 64})
    ->Args({7, 0, 64})
    ->Args({7, 1, 64})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
#endif

/// Hand-off cost of the pool: an empty parallel_for over `threads` (the fixed cost of one RBPF/PF region
/// per step) and one SpinBarrier round inside a region (the cost of each phase boundary in the reordered
/// RBPF's region). items = hand-offs or barrier rounds.
void BM_PoolParallelFor(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  rbpf::ThreadPool pool(threads);
  int sink = 0;
  for (auto _ : state) {
    pool.parallel_for(threads, [&](int, int, int t) {
      if (t == 0) ++sink;
    });
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}
BENCHMARK(BM_PoolParallelFor)->ArgNames({"threads"})->Arg(2)->Unit(benchmark::kNanosecond)->UseRealTime();

void BM_SpinBarrier(benchmark::State& state) {
  constexpr int kRounds = 1000;
  rbpf::ThreadPool pool(2);
  rbpf::SpinBarrier barrier;
  for (auto _ : state)
    pool.parallel_for(2, [&](int, int, int) {
      for (int r = 0; r < kRounds; ++r) barrier.arrive_and_wait(2);
    });
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kRounds);
}
BENCHMARK(BM_SpinBarrier)->Unit(benchmark::kMicrosecond)->UseRealTime();

/// The PF's bulk draws: args: kind (0 uniforms, 1 normals), avx2 (BatchRng::use_avx2; 1 runs the
/// default refills where the CPU has no AVX2). 384 variates a call, as one block of the PF on H2 (3 normals
/// a particle) or half a block's uniforms. items = variates: ns a variate = 1e9 / items_per_second.
void BM_BatchRng(benchmark::State& state) {
  BatchRng g(Rng(3));
  g.use_avx2(state.range(1) != 0);
  std::vector<double> out(384);
  for (auto _ : state) {
    if (state.range(0) == 0)
      g.fill_uniform(out.data(), 384);
    else
      g.fill_normal(out.data(), 384);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * 384);
  state.SetLabel(g.uses_avx2() ? "avx2 refills" : "default refills");
}
BENCHMARK(BM_BatchRng)
    ->ArgNames({"normal", "avx2"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kNanosecond);

/// args: particles, threads, resampling (0 systematic, 1 merge-select)
void BM_Pf(benchmark::State& state) {
  const H2Model& h = model();
  rbpf::PfOptions opt;
  opt.num_particles = static_cast<int>(state.range(0));
  opt.threads = static_cast<int>(state.range(1));
  opt.resampling = state.range(2) == 0 ? rbpf::PfResampling::kSystematic : rbpf::PfResampling::kMergeSelect;
  opt.ess_threshold = 0.5;
  rbpf::ParticleFilter<ConstantVelocityClock2> f(h.motion, h.st, h.proc, h.q, h.init, opt);
  std::size_t k = 0;
  for (auto _ : state) {
    const auto info = f.step(h.y[k & 1023], h.o[k & 1023]);
    benchmark::DoNotOptimize(info.log_likelihood);
    if ((++k & 1023) == 0) {
      state.PauseTiming();
      f.reset(h.init);
      state.ResumeTiming();
    }
  }
  // items = particle-steps: items_per_second gives ns per particle per step as 1e9 / rate
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Pf)
    ->ArgNames({"particles", "threads", "merge"})
    ->Args({100000, 1, 0})
    ->Args({100000, 2, 0})
    ->Args({1000000, 1, 0})
    ->Args({1000000, 2, 0})
    ->Args({1000000, 1, 1})
    ->Args({1000000, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
