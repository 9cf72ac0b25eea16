#pragma once
/// \file scenario.hpp
/// The simulation side of nlosloc (DESIGN.md, "The flow of data"): a Scenario turns (case, seed, run) into
/// one Draw (truth, measurements, sight, quality statistics, initial belief), an Estimator consumes a Draw
/// step by step and writes a position per step, and a Registry names the scenarios and, per scenario, the
/// estimators that can run on it (one registration line each, see registry.hpp).
///
/// Conventions: a Draw has T steps k = 0 .. T-1 at times t_k = k dt. The initial belief is a belief about the
/// state at k = 0 *before* y_0 is seen, so an estimator updates with y_0 without predicting and predicts then
/// updates for k >= 1. Matrices are row-major (one row per step) so numpy maps them without reshaping.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "nlosloc/core/random.hpp"
#include "nlosloc/core/types.hpp"
#include "nlosloc/models/measurement.hpp"

namespace nlosloc::detail {
/// A number as Scenario::description() and choices() print it: `digits` significant digits ("%.*g": no
/// trailing zeros, 0.01, 0.143, 1500), large values in full (20000, 1000000) and a short exponent (1e-5).
inline std::string fmt_num(double v, int digits = 6) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  std::string s = b;
  const std::size_t e = s.find('e');
  if (e == std::string::npos) return s;  // also "inf", "nan"
  if (s[e + 1] == '+' && std::abs(v) < 1e15) {
    std::snprintf(b, sizeof b, "%.0f", v);
    return b;
  }
  for (std::size_t i = e + 2; i + 1 < s.size() && s[i] == '0';) s.erase(i, 1);  // "1e-05" -> "1e-5"
  return s;
}
/// A point "(x, y)" in fmt_num's format.
inline std::string fmt_point(double x, double y) { return "(" + fmt_num(x) + ", " + fmt_num(y) + ")"; }
/// "Beta(a, b)", the quality statistic's law in the Huerta scenarios' choices.
inline std::string fmt_beta(double a, double b) { return "Beta(" + fmt_num(a) + ", " + fmt_num(b) + ")"; }
/// The choices' words for the first `discard` steps left out of the errors.
inline std::string fmt_discarded(int discard) {
  return discard == 0 ? std::string("no step discarded")
                      : "first " + std::to_string(discard) + " steps discarded";
}
}  // namespace nlosloc::detail

namespace nlosloc::sim {

/// Row-major dynamic matrices: one row per time step (numpy layout).
using RowMatX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatXi = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// One Monte Carlo realisation of a scenario case, generated from a single Rng(seed, run).
struct Draw {
  std::string scenario;    ///< scenario name
  std::string case_name;   ///< case name (one of Scenario::cases())
  int case_index = 0;      ///< its index in Scenario::cases()
  std::uint64_t seed = 0;  ///< seed of the generator
  std::uint64_t run = 0;   ///< run index = stream of the generator
  double dt = 0.0;         ///< sampling period (s)
  RowMatX states;          ///< T x n true states
  RowMatX positions;       ///< T x D true positions (m)
  RowMatX y;               ///< T x m measurements (rows of Scenario::measurements()); NaN = missing
  RowMatXi sight;          ///< T x B true sight condition per anchor (0 = LOS, 1.. = NLOS types)
  RowMatX quality;         ///< T x B quality statistics o_t; NaN when the scenario has none
  VecX initial_mean;       ///< n, mean of the initial belief (same for every estimator of the run)
  MatX initial_cov;        ///< n x n, covariance of the initial belief

  int steps() const { return static_cast<int>(y.rows()); }
};

/// A published number the bench prints beside ours, e.g. {"EKF", "2LOS/1NLOS", "p67", 309.2}.
struct PaperValue {
  std::string estimator;  ///< estimator name as registered (or to be registered) for the scenario
  std::string case_name;  ///< case name
  std::string metric;     ///< "p67", "p95" (percentile of the position error, m), "time_per_step_us", ...
  double value = 0.0;
};

/// A simulation scenario of reference/scenarios.md. Immutable after construction; draw() is const and
/// thread-safe, so one instance serves every Monte Carlo worker.
class Scenario {
 public:
  virtual ~Scenario() = default;

  /// Short name ("K1").
  virtual std::string name() const = 0;
  /// One-line description with the paper and section.
  virtual std::string description() const = 0;
  /// Values taken where the paper is silent, as printed by the bench (reference/scenarios.md "choice").
  virtual std::vector<std::string> choices() const = 0;
  /// Case names ("3LOS/0NLOS", ...).
  virtual std::vector<std::string> cases() const = 0;
  /// Default number of steps T of a run.
  virtual int steps() const = 0;
  /// Sampling period (s).
  virtual double dt() const = 0;
  /// B x D anchor positions (m).
  virtual MatX anchors() const = 0;
  /// First samples of every run left out of the statistics (the paper's transient).
  virtual int discard() const = 0;
  /// Size n of the true state (rows of Draw::states).
  virtual int state_dim() const = 0;
  /// The measurement stack that generated Draw::y (rows, anchors, per-condition noise); estimators use it.
  virtual const MeasurementStack& measurements() const = 0;
  /// Where the published numbers come from ("Ke & Wu 2011, Tables 1 and 2").
  virtual std::string paper_source() const { return {}; }
  /// The published numbers, for every estimator the paper reports (registered or not).
  virtual std::vector<PaperValue> paper() const { return {}; }

  /// Space dimension D (columns of anchors()).
  int space_dim() const { return static_cast<int>(measurements().anchors().cols()); }

  /// Index of `case_name` in cases(); throws std::invalid_argument listing the valid names.
  int case_index(const std::string& case_name) const {
    const std::vector<std::string> cs = cases();
    for (std::size_t i = 0; i < cs.size(); ++i)
      if (cs[i] == case_name) return static_cast<int>(i);
    std::string known;
    for (const auto& c : cs) known += (known.empty() ? "" : ", ") + c;
    detail::throw_invalid_argument("case: unknown case '" + case_name + "' of scenario " + name() +
                                   "; expected one of: " + known);
  }

  /// Published value of (estimator, case, metric), if the paper has one; an unknown case is
  /// std::invalid_argument (case_index), as a misspelt case would otherwise read as "no value".
  std::optional<double> paper_value(const std::string& estimator, const std::string& case_name,
                                    const std::string& metric) const {
    case_index(case_name);
    for (const PaperValue& v : paper())
      if (v.estimator == estimator && v.case_name == case_name && v.metric == metric) return v.value;
    return std::nullopt;
  }

  /// One realisation of case `case_name` from Rng(seed, run). `steps` > 0 overrides steps(); a shorter
  /// draw is the prefix of the longer one with the same (seed, run) (draws are generated step by step).
  Draw draw(const std::string& case_name, std::uint64_t seed, std::uint64_t run, int steps = 0) const {
    NLOSLOC_ENSURE(steps >= 0,
                   "steps: expected >= 0 (0 = the scenario's default), got " + std::to_string(steps));
    const int c = case_index(case_name);
    const int T = steps > 0 ? steps : this->steps();
    Rng rng(seed, run);
    Draw d;
    d.scenario = name();
    d.case_name = case_name;
    d.case_index = c;
    d.seed = seed;
    d.run = run;
    d.dt = dt();
    generate(c, T, rng, d);
    return d;
  }

 protected:
  /// Fills d.states, positions, y, sight, quality (T rows) and the initial belief for case index c,
  /// drawing every random number from rng.
  virtual void generate(int c, int T, Rng& rng, Draw& d) const = 0;
};

/// A position estimator seen by the Monte Carlo runner: one virtual call per step (the algorithm inside is
/// a template resolved at compile time, DESIGN.md / STYLE.md "type erasure at the filter level").
/// Constructed once per worker and case (allocation there), reset for each run.
class Estimator {
 public:
  virtual ~Estimator() = default;
  /// Display name.
  virtual std::string name() const = 0;
  /// Starts a run: takes the initial belief (and anything else it needs) from the draw. `rng` is this
  /// estimator's own stream for the run (particle filters draw from it; deterministic filters ignore it).
  virtual void reset(const Draw& draw, Rng& rng) = 0;
  /// Step k (0-based): measurement y_k (m, NaN rows missing), quality statistics o_k (B, may be NaN);
  /// writes the position estimate (D) into position_out. k = 0 is an update only (see file comment).
  virtual void step(int k, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o,
                    Eigen::Ref<VecX> position_out) = 0;
  /// True when the estimator classifies the sight of each anchor (RBPF, IUKF, NLOS tests); the runner
  /// then calls sight_estimate() after every step and scores it against the draw's true sight.
  virtual bool estimates_sight() const { return false; }
  /// Estimated sight condition of each anchor after the last step (B entries, argmax / decision);
  /// only called when estimates_sight() is true.
  virtual void sight_estimate(Eigen::Ref<VecXi> out) const { out.setZero(); }
};

/// Makes an estimator for a scenario and case index.
using EstimatorFactory = std::function<std::unique_ptr<Estimator>(const Scenario&, int case_index)>;

/// Names scenarios and, per scenario, the estimators that run on it. Filled once (registry.hpp), then
/// read-only and safe to share between threads.
class Registry {
 public:
  /// Registers a scenario instance under its name(); throws if the name is taken.
  void add_scenario(std::shared_ptr<const Scenario> s) {
    NLOSLOC_ENSURE(s != nullptr, "add_scenario: expected a scenario, got null");
    const std::string n = s->name();
    NLOSLOC_ENSURE(!has_scenario(n), "add_scenario: scenario '" + n + "' is already registered");
    order_.push_back(n);
    entries_[n].scenario = std::move(s);
  }
  /// Registers a default-constructed S.
  template <class S>
  void add_scenario() {
    add_scenario(std::make_shared<const S>());
  }

  /// Registers estimator `name` for `scenario`; `make(const S&, int case_index)` returns a
  /// std::unique_ptr<Estimator>, with S the scenario's concrete type (checked when called).
  template <class S, class Make>
  void add_estimator(const std::string& scenario, const std::string& name, Make make) {
    Entry& e = entry(scenario);
    for (const auto& kv : e.estimators)
      NLOSLOC_ENSURE(kv.first != name,
                     "add_estimator: estimator '" + name + "' is already registered for " + scenario);
    e.estimators.emplace_back(
        name, [make = std::move(make), scenario](const Scenario& s, int c) -> std::unique_ptr<Estimator> {
          const auto* typed = dynamic_cast<const S*>(&s);
          NLOSLOC_ENSURE(typed != nullptr, "estimator factory: registered for scenario " + scenario +
                                               ", called with scenario " + s.name());
          return make(*typed, c);
        });
  }

  /// Scenario names in registration order.
  const std::vector<std::string>& scenarios() const { return order_; }
  bool has_scenario(const std::string& n) const { return entries_.count(n) != 0; }
  /// The scenario named n; throws std::invalid_argument listing the valid names.
  const Scenario& scenario(const std::string& n) const { return *entry(n).scenario; }
  std::shared_ptr<const Scenario> scenario_ptr(const std::string& n) const { return entry(n).scenario; }

  /// Estimator names registered for a scenario, in registration order.
  std::vector<std::string> estimators(const std::string& scenario) const {
    std::vector<std::string> r;
    for (const auto& kv : entry(scenario).estimators) r.push_back(kv.first);
    return r;
  }
  /// Factory of (scenario, estimator); throws std::invalid_argument listing the valid names.
  const EstimatorFactory& estimator(const std::string& scenario, const std::string& name) const {
    const Entry& e = entry(scenario);
    for (const auto& kv : e.estimators)
      if (kv.first == name) return kv.second;
    std::string known;
    for (const auto& kv : e.estimators) known += (known.empty() ? "" : ", ") + kv.first;
    detail::throw_invalid_argument("estimator: unknown estimator '" + name + "' for scenario " + scenario +
                                   "; expected one of: " + (known.empty() ? "(none registered)" : known));
  }

 private:
  struct Entry {
    std::shared_ptr<const Scenario> scenario;
    std::vector<std::pair<std::string, EstimatorFactory>> estimators;
  };
  const Entry& entry(const std::string& n) const {
    auto it = entries_.find(n);
    if (it == entries_.end()) unknown(n);
    return it->second;
  }
  Entry& entry(const std::string& n) {
    auto it = entries_.find(n);
    if (it == entries_.end()) unknown(n);
    return it->second;
  }
  [[noreturn]] void unknown(const std::string& n) const {
    std::string known;
    for (const auto& s : order_) known += (known.empty() ? "" : ", ") + s;
    detail::throw_invalid_argument("scenario: unknown scenario '" + n +
                                   "'; expected one of: " + (known.empty() ? "(none registered)" : known));
  }
  std::vector<std::string> order_;
  std::map<std::string, Entry> entries_;
};

}  // namespace nlosloc::sim
