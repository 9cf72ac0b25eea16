/// \file nlosloc_bench.cpp
/// nlosloc-bench: runs the paper scenarios of reference/scenarios.md and prints our numbers beside the
/// paper's, with the choices each scenario made.
///
///   nlosloc-bench list
///   nlosloc-bench run K1 --runs 100 --seed 1 [--threads T] [--case C ...] [--estimators E ...]
///                        [--steps T] [--first-run F] [--json FILE] [--quick] [--quiet]
///
/// --first-run F runs F .. F + runs - 1, each exactly as in a run from 0: `--first-run 57 --runs 1` replays
/// run 57 of a long run alone (the tables then name the runs). The JSON keeps pooled statistics only, so
/// chunks of one long run are joined in Python (nlosloc.montecarlo.merge), not from these files.
///
/// Progress goes to stderr, tables to stdout; exit code 2 on a bad argument (unknown scenario, case or
/// estimator, a value out of range such as --steps 0 or --seed -1, or one that does not parse), 1 on any
/// other failure.
#include <fmt/core.h>
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_decimal.hpp"
#include "nlosloc/sim/k2.hpp"
#include "nlosloc/sim/k3.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/registry.hpp"
#include "nlosloc/sim/report.hpp"

namespace {

using nlosloc::sim::Registry;
using nlosloc::sim::Scenario;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

/// Bad command-line values: reported with exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string join(const std::vector<std::string>& v, const char* sep = ", ") {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

/// Progress on stderr: a bar redrawn in place on a terminal, a line per quarter otherwise.
class Progress {
 public:
  Progress(std::string label, bool enabled)
      : label_(std::move(label)), enabled_(enabled), tty_(isatty(2) != 0) {}

  void operator()(int done, int total) {
    if (!enabled_) return;
    const double elapsed = std::chrono::duration<double>(Clock::now() - t0_).count();
    if (tty_) {
      const bool last = done == total;
      if (!last && elapsed - last_draw_ < 0.1 && done != 0) return;
      last_draw_ = elapsed;
      constexpr int kWidth = 30;
      const int filled = total > 0 ? done * kWidth / total : kWidth;
      fmt::print(stderr, "\r{} [{}{}] {}/{} runs  {:.1f} s{}", label_, std::string(filled, '#'),
                 std::string(kWidth - filled, '.'), done, total, elapsed, last ? "\n" : "");
    } else {
      const int quarter = total > 0 ? 4 * done / total : 4;
      if (quarter == last_quarter_) return;
      last_quarter_ = quarter;
      fmt::print(stderr, "{}: {}/{} runs  {:.1f} s\n", label_, done, total, elapsed);
    }
    std::fflush(stderr);
  }

 private:
  std::string label_;
  bool enabled_, tty_;
  Clock::time_point t0_ = Clock::now();
  double last_draw_ = -1.0;
  int last_quarter_ = -1;
};

int cmd_list(const Registry& reg) {
  for (const std::string& name : reg.scenarios()) {
    const Scenario& s = reg.scenario(name);
    const auto est = reg.estimators(name);
    fmt::print("{}  cases: {}  |  estimators: {}  |  {}\n", name, join(s.cases()),
               est.empty() ? std::string("(none)") : join(est), s.description());
  }
  return 0;
}

struct RunArgs {
  std::string scenario;
  int runs = 100;
  std::uint64_t first_run = 0;
  std::uint64_t seed = 1;
  int threads = 0;
  int steps = 0;
  std::vector<std::string> cases;
  std::vector<std::string> estimators;
  std::string json;
  bool quick = false;
  bool quiet = false;
};

Json percentiles_json(const nlosloc::sim::EstimatorSummary& e) {
  Json j = Json::object();
  for (std::size_t i = 0; i < e.levels.size(); ++i) j[fmt::format("{:g}", e.levels[i])] = e.percentiles[i];
  return j;
}

Json optional_json(const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); }

int cmd_run(const Registry& reg, RunArgs a) {
  namespace sim = nlosloc::sim;
  if (!reg.has_scenario(a.scenario))
    throw UsageError("unknown scenario '" + a.scenario + "'; expected one of: " + join(reg.scenarios()));
  const Scenario& s = reg.scenario(a.scenario);
  const std::vector<std::string> all_cases = s.cases();
  const std::vector<std::string> registered = reg.estimators(a.scenario);
  if (a.cases.empty()) a.cases = all_cases;
  for (const auto& c : a.cases)
    if (std::find(all_cases.begin(), all_cases.end(), c) == all_cases.end())
      throw UsageError("unknown case '" + c + "' of scenario " + a.scenario +
                       "; expected one of: " + join(all_cases));
  if (a.estimators.empty()) a.estimators = registered;
  for (const auto& e : a.estimators)
    if (std::find(registered.begin(), registered.end(), e) == registered.end())
      throw UsageError("unknown estimator '" + e + "' for scenario " + a.scenario + "; expected one of: " +
                       (registered.empty() ? std::string("(none registered)") : join(registered)));
  if (a.estimators.empty()) throw UsageError("scenario " + a.scenario + " has no registered estimator");
  // results are keyed by name in the tables and the JSON: a repeat would run twice and keep one
  const auto refuse_repeats = [](const std::vector<std::string>& v, const char* option) {
    for (auto it = v.begin(); it != v.end(); ++it)
      if (std::find(v.begin(), it, *it) != it)
        throw UsageError(std::string(option) + ": '" + *it + "' given more than once");
  };
  refuse_repeats(a.cases, "--case");
  refuse_repeats(a.estimators, "--estimators");
  if (a.runs < 1) throw UsageError("--runs: expected >= 1, got " + std::to_string(a.runs));
  if (a.first_run > std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(a.runs - 1))
    throw UsageError("--first-run: expected --first-run + --runs - 1 <= 18446744073709551615, got " +
                     std::to_string(a.first_run) + " with --runs " + std::to_string(a.runs));
  if (a.threads < 0)
    throw UsageError("--threads: expected >= 0 (0 = all cores), got " + std::to_string(a.threads));
  const int steps = a.steps > 0 ? a.steps : s.steps();
  if (steps <= s.discard())
    throw UsageError("--steps: expected more than the " + std::to_string(s.discard()) +
                     " discarded samples, got " + std::to_string(steps));

  if (!a.json.empty()) {  // found now, not after the whole run
    const std::filesystem::path path(a.json);
    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
    if (!std::filesystem::is_directory(dir) || ::access(dir.c_str(), W_OK) != 0 ||
        std::filesystem::is_directory(path))
      throw UsageError("--json: cannot write " + a.json + " (its directory is missing or not writable)");
  }

  const auto t0 = Clock::now();
  fmt::print("{}\n", sim::format_choices(s));
  std::fflush(stdout);

  Json results = Json::object();
  int threads_used = 0;
  std::string extra;  // scenario-specific metrics printed after the tables (K3: P(error <= 5 m))
  for (const std::string& c : a.cases) {
    sim::MonteCarloOptions opt;
    opt.runs = a.runs;
    opt.first_run = a.first_run;
    opt.seed = a.seed;
    opt.threads = a.threads;
    opt.steps = steps;
    Progress bar(a.scenario + " " + c, !a.quiet);
    opt.progress = [&bar](int done, int total) { bar(done, total); };
    const sim::MonteCarloResult r = sim::run_monte_carlo(reg, a.scenario, c, a.estimators, opt);
    threads_used = r.threads;
    const sim::CaseSummary sum = sim::summarize(s, r);
    fmt::print("{}\n", sim::format_table(sum));
    std::fflush(stdout);
    if (const auto* k3 = dynamic_cast<const sim::K3*>(&s))  // Sec. 6.4's P(error <= threshold)
      extra += sim::format_k3_probability(r, k3->params().threshold);

    if (!a.json.empty()) {
      Json ests = Json::object();
      for (std::size_t i = 0; i < r.estimators.size(); ++i) {
        const sim::EstimatorRuns& er = r.estimators[i];
        const sim::EstimatorSummary& es = sum.estimators[i];
        const sim::Ecdf cdf = sim::ecdf(sim::pooled_errors(er.errors, r.discard), 1000);
        const nlosloc::VecX rmse = sim::rmse_over_time(er.errors);
        ests[er.name] = {
            {"percentiles", percentiles_json(es)},
            {"ecdf", {{"x", cdf.x}, {"p", cdf.p}}},
            {"rmse", std::vector<double>(rmse.data(), rmse.data() + rmse.size())},
            {"time_per_step_ns",
             {{"mean", es.time_per_step_ns},
              {"runs", std::vector<double>(er.time_per_step_ns.data(),
                                           er.time_per_step_ns.data() + er.time_per_step_ns.size())}}},
            {"sight_accuracy", optional_json(es.sight_accuracy)},
            {"paper",
             {{"p67", optional_json(es.paper_p67)},
              {"p95", optional_json(es.paper_p95)},
              {"time_per_step_us", optional_json(es.paper_time_per_step_us)}}},
        };
      }
      results[c] = {{"wall_seconds", r.wall_seconds}, {"estimators", ests}};
    }
  }
  if (a.scenario == "K3") fmt::print("K3: probability that the position error is at most 5 m\n{}\n", extra);
  if (a.scenario == "K2")  // identification per sample, ranging and position error (Ke & Wu Figs. 3-5)
    fmt::print("{}\n", sim::format_k2_study(
                           sim::run_k2_study(reg, a.runs, a.seed, steps, a.estimators, a.first_run)));
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  fmt::print("total wall time {:.2f} s ({} threads)\n", wall, threads_used);

  if (!a.json.empty()) {
    Json paper = Json::array();
    for (const auto& v : s.paper())
      paper.push_back(
          {{"estimator", v.estimator}, {"case", v.case_name}, {"metric", v.metric}, {"value", v.value}});
    Json doc = {
        {"tool", "nlosloc-bench"},
        {"config",
         {{"scenario", a.scenario},
          {"cases", a.cases},
          {"estimators", a.estimators},
          {"runs", a.runs},
          {"first_run", a.first_run},
          {"seed", a.seed},
          {"threads", threads_used},
          {"steps", steps},
          {"discard", s.discard()},
          {"dt", s.dt()},
          {"quick", a.quick},
          {"percentile_method", "linear interpolation (numpy.percentile default)"},
          {"ecdf_max_points", 1000}}},
        {"description", s.description()},
        {"choices", s.choices()},
        {"paper", {{"source", s.paper_source()}, {"values", paper}}},
        {"results", results},
        {"wall_seconds", wall},
    };
    std::ofstream f(a.json);
    if (!f) throw std::runtime_error("cannot open '" + a.json + "' for writing");
    f << doc.dump(1) << "\n";
    if (!f) throw std::runtime_error("failed writing '" + a.json + "'");
    fmt::print(stderr, "wrote {}\n", a.json);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nlosloc-bench: paper scenarios of nlosloc, our numbers beside the paper's"};
  app.require_subcommand(1);
  CLI::App* list = app.add_subcommand("list", "List scenarios, their cases and registered estimators");
  CLI::App* run = app.add_subcommand("run", "Run a scenario's Monte Carlo and print the tables");
  RunArgs a;
  run->add_option("scenario", a.scenario, "Scenario name (see list)")->required();
  // decimal(): CLI11 alone reads "010" as 8 and clamps out-of-range values (and strtoull turns "-1" into
  // 2^64 - 1); negative counts pass to the checks below, which name them.
  const unsigned long long int_max = static_cast<unsigned long long>(std::numeric_limits<int>::max());
  CLI::Option* runs_opt = run->add_option("--runs,-n", a.runs, "Monte Carlo runs (default 100)")
                              ->transform(nlosloc::bench::decimal(int_max, true));
  run->add_option("--first-run", a.first_run,
                  "Index of the first run: runs F .. F + runs - 1, each as in a run from 0 (default 0)")
      ->transform(nlosloc::bench::decimal(std::numeric_limits<std::uint64_t>::max()));
  run->add_option("--seed,-s", a.seed, "Seed: run r draws from Rng(seed, r) (default 1)")
      ->transform(nlosloc::bench::decimal(std::numeric_limits<std::uint64_t>::max()));
  run->add_option("--threads,-t", a.threads, "Worker threads (default 0 = all cores)")
      ->transform(nlosloc::bench::decimal(int_max, true));
  CLI::Option* steps_opt = run->add_option("--steps", a.steps, "Steps per run (default: the scenario's)")
                               ->transform(nlosloc::bench::decimal(int_max, true));
  run->add_option("--case,-c", a.cases, "Cases to run (default all)");
  run->add_option("--estimators,-e", a.estimators, "Estimators to run (default all registered)");
  run->add_option("--json", a.json,
                  "Write config, choices, percentiles, ECDF, RMSE, timings, paper values (replaces FILE)");
  run->add_flag("--quick", a.quick, "Short check: 5 runs x 400 steps unless --runs/--steps are given");
  run->add_flag("--quiet,-q", a.quiet, "No progress on stderr");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints help or the error; CLI11's own codes (100+) would break the promise of 2 above.
    return app.exit(e) == static_cast<int>(CLI::ExitCodes::Success) ? 0 : 2;
  }
  try {
    const Registry& reg = nlosloc::sim::registry();
    if (list->parsed()) return cmd_list(reg);
    if (run->parsed()) {
      // 0 is the internal "scenario default": given explicitly, 0 or less is a mistake, not a request.
      if (steps_opt->count() > 0 && a.steps < 1)
        throw UsageError("--steps: expected >= 1, got " + std::to_string(a.steps));
      if (a.quick) {
        if (runs_opt->count() == 0) a.runs = 5;
        if (steps_opt->count() == 0) a.steps = 400;
      }
      return cmd_run(reg, a);
    }
  } catch (const UsageError& e) {
    fmt::print(stderr, "nlosloc-bench: error: {}\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    fmt::print(stderr, "nlosloc-bench: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "nlosloc-bench: failed: {}\n", e.what());
    return 1;
  }
  return 0;
}
