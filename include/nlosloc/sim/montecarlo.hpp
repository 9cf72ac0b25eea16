#pragma once
/// \file montecarlo.hpp
/// Monte Carlo runner: every estimator runs on identical draws (each run's Draw is generated once and fed
/// to every estimator), runs are spread over std::thread workers by an atomic counter, and the result does
/// not depend on the number of threads (run r always uses Rng(seed, r) for its draw and the estimator
/// stream below, and writes row r of the result).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "nlosloc/core/random.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc::sim {

/// Options of run_monte_carlo.
struct MonteCarloOptions {
  int runs = 100;          ///< number of runs N >= 1 (Ke & Wu Sec. 6: N = 100)
  std::uint64_t seed = 1;  ///< seed; run r draws from Rng(seed, r)
  /// Index of the first run: the runs are first_run .. first_run + runs - 1, each the same as in a run from
  /// 0, so runs split into chunks (other processes or machines) join into one result, row for row.
  std::uint64_t first_run = 0;
  int threads = 0;  ///< worker threads; 0 = std::thread::hardware_concurrency()
  int steps = 0;    ///< steps per run; 0 = the scenario's default
  /// Called on the calling thread with (runs done, runs) at the start and whenever runs complete.
  /// May throw to cancel (workers stop after their current run; the exception is rethrown).
  std::function<void(int done, int total)> progress;
  /// Called on the calling thread about every poll_interval_ms while workers run (e.g. to check for
  /// Ctrl-C); may throw to cancel, like progress.
  std::function<void()> poll;
  int poll_interval_ms = 100;  ///< > 0
};

}  // namespace nlosloc::sim

namespace nlosloc::detail {
/// The runs first_run .. first_run + runs - 1 (runs >= 1) must be indices of Rng streams.
inline void check_first_run(std::uint64_t first_run, int runs) {
  NLOSLOC_ENSURE(
      first_run <= std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(runs - 1),
      "first_run: expected first_run + runs - 1 <= 2^64 - 1, got first_run " + std::to_string(first_run) +
          " and runs " + std::to_string(runs));
}

/// "N runs" or, for a chunk that does not start at run 0, "N runs (runs F..L)" ("1 run (run F)"): a table of
/// runs 40..59 must not read as runs 0..19.
inline std::string runs_label(int runs, std::uint64_t first_run) {
  std::string s = std::to_string(runs) + (runs == 1 ? " run" : " runs");
  if (first_run == 0) return s;
  if (runs == 1) return s + " (run " + std::to_string(first_run) + ")";
  return s + " (runs " + std::to_string(first_run) + ".." +
         std::to_string(first_run + static_cast<std::uint64_t>(runs) - 1) + ")";
}
}  // namespace nlosloc::detail

namespace nlosloc::sim {

/// A named estimator factory given to the runner.
struct EstimatorSpec {
  std::string name;
  EstimatorFactory make;
};

/// Per-estimator output of a Monte Carlo run.
struct EstimatorRuns {
  std::string name;
  RowMatX errors;         ///< runs x T position error norms ||p_hat_k - p_k|| (m)
  VecX time_per_step_ns;  ///< runs: wall time of the run's step loop (steady_clock) / T, ns
  /// runs x T fraction of anchors whose estimated sight equals the true sight at step k; empty when the
  /// estimator does not estimate sight (Estimator::estimates_sight()).
  RowMatX sight_accuracy;
  /// runs x B fraction of steps k >= discard at which anchor b was classified correctly; empty likewise.
  RowMatX sight_anchor_accuracy;
};

/// Output of run_monte_carlo.
struct MonteCarloResult {
  std::string scenario;
  std::string case_name;
  int case_index = 0;
  int runs = 0;
  std::uint64_t first_run = 0;  ///< row r of every matrix is run first_run + r
  int steps = 0;
  int discard = 0;  ///< the scenario's discard (statistics use steps k >= discard)
  int threads = 0;  ///< workers actually used
  std::uint64_t seed = 0;
  double dt = 0.0;
  double wall_seconds = 0.0;
  std::vector<EstimatorRuns> estimators;  ///< in the order given

  /// Output of the estimator called `name`; throws std::invalid_argument if absent.
  const EstimatorRuns& estimator(const std::string& name) const {
    for (const auto& e : estimators)
      if (e.name == name) return e;
    nlosloc::detail::throw_invalid_argument("estimator: '" + name + "' is not in this result");
  }
};

/// Seed of estimator `name`'s generator: seed mixed with the FNV-1a hash of the name, so an estimator's
/// stream for run r, Rng(estimator_seed(seed, name), r), is the same whatever other estimators run beside it
/// and differs from the draw's Rng(seed, r).
inline std::uint64_t estimator_seed(std::uint64_t seed, const std::string& name) {
  std::uint64_t h = 0xCBF29CE484222325ULL;  // FNV-1a 64-bit offset basis
  for (unsigned char ch : name) h = (h ^ ch) * 0x100000001B3ULL;
  h ^= 0xE57A'0000'0000'0001ULL;  // never 0, so the estimator seed differs from the draw seed
  return seed ^ h;
}

/// Checks a list of estimators for a run: at least one, each with a factory, no name twice (results are
/// keyed by name: a repeat would overwrite the first). std::invalid_argument naming the estimator.
inline void check_estimator_specs(const std::vector<EstimatorSpec>& estimators) {
  NLOSLOC_ENSURE(!estimators.empty(), "estimators: expected at least one estimator");
  for (std::size_t i = 0; i < estimators.size(); ++i) {
    NLOSLOC_ENSURE(bool(estimators[i].make), "estimators: '" + estimators[i].name + "' has no factory");
    for (std::size_t j = 0; j < i; ++j)
      NLOSLOC_ENSURE(estimators[j].name != estimators[i].name,
                     "estimators: '" + estimators[i].name + "' appears more than once");
  }
}

/// Runs `estimators` on `opt.runs` draws of case `case_name` of `scenario`. Every draw is generated once
/// per run and fed to every estimator (each estimator made once per worker, reset per run); each estimator
/// gets Rng(estimator_seed(seed, name), run). Exceptions from a factory, an estimator or a callback stop the
/// workers and are rethrown here. Results are bit-identical for any number of threads.
inline MonteCarloResult run_monte_carlo(const Scenario& scenario, const std::string& case_name,
                                        const std::vector<EstimatorSpec>& estimators,
                                        const MonteCarloOptions& opt = {}) {
  NLOSLOC_ENSURE(opt.runs >= 1, "runs: expected >= 1, got " + std::to_string(opt.runs));
  detail::check_first_run(opt.first_run, opt.runs);
  NLOSLOC_ENSURE(opt.threads >= 0,
                 "threads: expected >= 0 (0 = all cores), got " + std::to_string(opt.threads));
  NLOSLOC_ENSURE(opt.steps >= 0,
                 "steps: expected >= 0 (0 = the scenario's default), got " + std::to_string(opt.steps));
  NLOSLOC_ENSURE(opt.poll_interval_ms > 0, "poll_interval_ms: expected > 0");
  check_estimator_specs(estimators);
  const int steps = opt.steps > 0 ? opt.steps : scenario.steps();
  NLOSLOC_ENSURE(steps > scenario.discard(), "steps: expected more than the scenario's " +
                                                 std::to_string(scenario.discard()) +
                                                 " discarded first steps, got " + std::to_string(steps));

  const auto wall0 = std::chrono::steady_clock::now();
  MonteCarloResult res;
  res.scenario = scenario.name();
  res.case_name = case_name;
  res.case_index = scenario.case_index(case_name);
  res.runs = opt.runs;
  res.first_run = opt.first_run;
  res.steps = steps;
  res.discard = scenario.discard();
  res.seed = opt.seed;
  res.dt = scenario.dt();
  int hw = opt.threads > 0 ? opt.threads : static_cast<int>(std::thread::hardware_concurrency());
  res.threads = std::max(1, std::min(hw, opt.runs));

  const int T = res.steps, R = opt.runs, D = scenario.space_dim();
  const auto E = estimators.size();
  res.estimators.resize(E);
  std::vector<std::uint64_t> est_seed(E);
  for (std::size_t e = 0; e < E; ++e) {
    res.estimators[e].name = estimators[e].name;
    res.estimators[e].errors.setZero(R, T);
    res.estimators[e].time_per_step_ns.setZero(R);
    est_seed[e] = estimator_seed(opt.seed, estimators[e].name);
  }

  std::atomic<int> next{0};
  std::atomic<bool> stop{false};
  std::mutex mu;
  std::condition_variable cv;
  int done = 0, exited = 0;
  std::exception_ptr error;

  auto worker = [&]() {
    try {
      std::vector<std::unique_ptr<Estimator>> est;
      for (const auto& spec : estimators) {
        est.push_back(spec.make(scenario, res.case_index));
        NLOSLOC_ENSURE(est.back() != nullptr, "estimators: factory of '" + spec.name + "' returned null");
      }
      MatX pos(D, T), Yt, Ot;     // column k = step k (contiguous, so step() binds without copies)
      Eigen::MatrixXi sight_hat;  // B x T estimated sight, when an estimator provides it
      while (!stop.load(std::memory_order_relaxed)) {
        const int r = next.fetch_add(1);
        if (r >= R) break;
        const std::uint64_t run = opt.first_run + static_cast<std::uint64_t>(r);  // row r
        const Draw d = scenario.draw(case_name, opt.seed, run, T);
        Yt = d.y.transpose();
        Ot = d.quality.transpose();
        for (std::size_t e = 0; e < E; ++e) {
          Rng rng(est_seed[e], run);
          est[e]->reset(d, rng);
          const bool sighted = est[e]->estimates_sight();
          const auto B = static_cast<Eigen::Index>(d.sight.cols());
          if (sighted) sight_hat.setZero(B, T);
          const auto t0 = std::chrono::steady_clock::now();
          for (int k = 0; k < T; ++k) {
            est[e]->step(k, Yt.col(k), Ot.col(k), pos.col(k));
            if (sighted) est[e]->sight_estimate(sight_hat.col(k));
          }
          const auto t1 = std::chrono::steady_clock::now();
          auto& out = res.estimators[e];
          if (sighted) {
            std::lock_guard<std::mutex> lk(mu);  // first run sizes the shared matrices
            if (out.sight_accuracy.size() == 0) {
              out.sight_accuracy.setConstant(R, T, std::numeric_limits<double>::quiet_NaN());
              out.sight_anchor_accuracy.setConstant(R, B, std::numeric_limits<double>::quiet_NaN());
            }
          }
          if (sighted) {
            const int from = scenario.discard();  // < T (checked above)
            for (Eigen::Index b = 0; b < B; ++b) {
              int hits = 0;
              for (int k = from; k < T; ++k) hits += sight_hat(b, k) == d.sight(k, b);
              out.sight_anchor_accuracy(r, b) = static_cast<double>(hits) / (T - from);
            }
            for (int k = 0; k < T; ++k) {
              int hits = 0;
              for (Eigen::Index b = 0; b < B; ++b) hits += sight_hat(b, k) == d.sight(k, b);
              out.sight_accuracy(r, k) = B > 0 ? static_cast<double>(hits) / static_cast<double>(B) : 0.0;
            }
          }
          for (int k = 0; k < T; ++k) out.errors(r, k) = (pos.col(k) - d.positions.row(k).transpose()).norm();
          out.time_per_step_ns[r] =
              static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count()) / T;
        }
        {
          std::lock_guard<std::mutex> lk(mu);
          ++done;
        }
        cv.notify_all();
      }
    } catch (...) {
      std::lock_guard<std::mutex> lk(mu);
      if (!error) error = std::current_exception();
      stop = true;
    }
    {
      std::lock_guard<std::mutex> lk(mu);
      ++exited;
    }
    cv.notify_all();
  };

  // Joins the workers on every exit path (a throwing callback included).
  struct Pool {
    std::vector<std::thread> threads;
    std::atomic<bool>* stop;
    ~Pool() {
      stop->store(true);
      for (auto& t : threads)
        if (t.joinable()) t.join();
    }
  } pool{{}, &stop};
  pool.threads.reserve(static_cast<std::size_t>(res.threads));
  for (int i = 0; i < res.threads; ++i) pool.threads.emplace_back(worker);

  int reported = -1;
  for (;;) {
    int now_done, now_exited;
    bool failed;
    {
      std::unique_lock<std::mutex> lk(mu);
      cv.wait_for(lk, std::chrono::milliseconds(opt.poll_interval_ms),
                  [&] { return done != reported || exited == res.threads; });
      now_done = done;
      now_exited = exited;
      failed = error != nullptr;
    }
    if (now_done != reported && !failed) {
      reported = now_done;
      if (opt.progress) opt.progress(now_done, R);
    }
    if (now_exited == res.threads) break;
    if (opt.poll && !failed) opt.poll();
  }
  for (auto& t : pool.threads) t.join();
  if (error) std::rethrow_exception(error);
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return res;
}

/// Runs the estimators registered under `names` (empty: all registered) for scenario `scenario_name` of
/// registry `reg`; throws std::invalid_argument on an unknown scenario, case or estimator name.
inline MonteCarloResult run_monte_carlo(const Registry& reg, const std::string& scenario_name,
                                        const std::string& case_name, const std::vector<std::string>& names,
                                        const MonteCarloOptions& opt = {}) {
  const Scenario& s = reg.scenario(scenario_name);
  s.case_index(case_name);  // validate before starting threads
  const std::vector<std::string> use = names.empty() ? reg.estimators(scenario_name) : names;
  std::vector<EstimatorSpec> specs;
  for (const auto& n : use) specs.push_back({n, reg.estimator(scenario_name, n)});
  return run_monte_carlo(s, case_name, specs, opt);
}

}  // namespace nlosloc::sim
