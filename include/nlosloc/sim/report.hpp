#pragma once
/// \file report.hpp
/// Summaries of Monte Carlo results beside the paper's numbers, and their plain-text rendering (the tables
/// nlosloc-bench prints). No formatting library needed: the bench adds JSON and progress on top.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc::sim {

/// Percentile levels reported by default (%): the median, the FCC's 67% and 95% (Ke & Wu Table 1), and 90%.
inline std::vector<double> default_levels() { return {50.0, 67.0, 90.0, 95.0}; }

/// Summary of one estimator on one case.
struct EstimatorSummary {
  std::string name;
  std::vector<double> levels;       ///< percentile levels (%)
  std::vector<double> percentiles;  ///< position error at each level over runs and steps k >= discard (m)
  double time_per_step_ns = 0.0;    ///< mean over runs of the per-run time per step (ns)
  std::optional<double> paper_p67, paper_p95;    ///< published 67% / 95% errors (m), if any
  std::optional<double> paper_time_per_step_us;  ///< published time per step (us), if any
  /// Fraction of (anchor, step k >= discard) pairs whose sight was classified correctly, for estimators
  /// that classify sight (Estimator::estimates_sight); empty otherwise.
  std::optional<double> sight_accuracy;

  /// Percentile at `level` (one of levels); NaN if it was not computed.
  double at(double level) const {
    for (std::size_t i = 0; i < levels.size(); ++i)
      if (levels[i] == level) return percentiles[i];
    return std::nan("");
  }
};

/// Summary of one case: one entry per estimator, in the result's order.
struct CaseSummary {
  std::string scenario;
  std::string case_name;
  int runs = 0;
  std::uint64_t first_run = 0;  ///< the runs are first_run .. first_run + runs - 1
  int steps = 0;
  int discard = 0;
  double wall_seconds = 0.0;
  std::vector<EstimatorSummary> estimators;
};

/// Percentiles (pooled over runs and steps k >= discard), mean time per step and the paper's values.
inline CaseSummary summarize(const Scenario& s, const MonteCarloResult& r,
                             const std::vector<double>& levels = default_levels()) {
  CaseSummary c;
  c.scenario = r.scenario;
  c.case_name = r.case_name;
  c.runs = r.runs;
  c.first_run = r.first_run;
  c.steps = r.steps;
  c.discard = r.discard;
  c.wall_seconds = r.wall_seconds;
  for (const EstimatorRuns& e : r.estimators) {
    EstimatorSummary m;
    m.name = e.name;
    m.levels = levels;
    m.percentiles = percentiles(pooled_errors(e.errors, r.discard), levels);
    m.time_per_step_ns = mean_of(e.time_per_step_ns);
    m.paper_p67 = s.paper_value(e.name, r.case_name, "p67");
    m.paper_p95 = s.paper_value(e.name, r.case_name, "p95");
    m.paper_time_per_step_us = s.paper_value(e.name, r.case_name, "time_per_step_us");
    if (e.sight_anchor_accuracy.size() > 0) m.sight_accuracy = e.sight_anchor_accuracy.mean();
    c.estimators.push_back(std::move(m));
  }
  return c;
}

}  // namespace nlosloc::sim

namespace nlosloc::detail {
/// A table cell: the value with format f, or "-" when absent or NaN.
inline std::string report_num(std::optional<double> v, const char* f = "%10.2f") {
  char b[64];
  if (!v || std::isnan(*v)) {
    std::snprintf(b, sizeof b, "%10s", "-");
  } else {
    std::snprintf(b, sizeof b, f, *v);
  }
  return b;
}
/// ours / paper when the paper has a positive value.
inline std::optional<double> report_ratio(double ours, std::optional<double> paper) {
  if (!paper || !(*paper > 0.0)) return std::nullopt;
  return ours / *paper;
}
/// First line of a case table.
inline std::string case_header(const sim::CaseSummary& c) {
  char b[512];
  std::snprintf(b, sizeof b, "%s case %s: %s x %d steps, errors over steps k >= %d, %.2f s\n",
                c.scenario.c_str(), c.case_name.c_str(), runs_label(c.runs, c.first_run).c_str(), c.steps,
                c.discard, c.wall_seconds);
  return b;
}
}  // namespace nlosloc::detail

namespace nlosloc::sim {

inline std::string format_percentile_table(const CaseSummary& c);

/// The case table: estimator, ours 67% / 95%, paper 67% / 95%, ratios ours/paper, time per step (ours and
/// the paper's, whose hardware and language differ: Ke & Wu ran Matlab on a Pentium IV). When no estimator
/// of the case has a published number (papers that give CDFs only, e.g. Huerta Figs. 13-15), the table of
/// format_percentile_table() is printed instead.
inline std::string format_table(const CaseSummary& c) {
  bool any_paper = false;
  for (const EstimatorSummary& e : c.estimators)
    any_paper = any_paper || e.paper_p67 || e.paper_p95 || e.paper_time_per_step_us;
  if (!any_paper) return format_percentile_table(c);
  std::string out;
  char b[512];
  out += detail::case_header(c);
  std::snprintf(b, sizeof b, "  %-20s %10s %10s %10s %10s %10s %10s %10s %10s %10s\n", "estimator",
                "ours 67%", "ours 95%", "paper 67%", "paper 95%", "ratio 67%", "ratio 95%", "us/step",
                "paper us", "sight acc");
  out += b;
  for (const EstimatorSummary& e : c.estimators) {
    const double p67 = e.at(67.0), p95 = e.at(95.0);
    out += "  ";
    std::snprintf(b, sizeof b, "%-20s", e.name.c_str());
    out += b;
    out += " " + detail::report_num(p67) + " " + detail::report_num(p95) + " " +
           detail::report_num(e.paper_p67) + " " + detail::report_num(e.paper_p95);
    out += " " + detail::report_num(detail::report_ratio(p67, e.paper_p67), "%10.3f") + " " +
           detail::report_num(detail::report_ratio(p95, e.paper_p95), "%10.3f");
    out += " " + detail::report_num(e.time_per_step_ns * 1e-3, "%10.3f") + " " +
           detail::report_num(e.paper_time_per_step_us) + " " +
           detail::report_num(e.sight_accuracy, "%10.3f") + "\n";
  }
  return out;
}

/// The case table without paper columns: estimator, our 50% / 67% / 90% / 95% errors, time per step and
/// sight classification accuracy (scenarios whose paper publishes CDFs only).
inline std::string format_percentile_table(const CaseSummary& c) {
  std::string out;
  char b[512];
  out += detail::case_header(c);
  std::snprintf(b, sizeof b, "  %-20s %10s %10s %10s %10s %10s %10s\n", "estimator", "ours 50%", "ours 67%",
                "ours 90%", "ours 95%", "us/step", "sight acc");
  out += b;
  for (const EstimatorSummary& e : c.estimators) {
    std::snprintf(b, sizeof b, "  %-20s", e.name.c_str());
    out += b;
    for (double q : {50.0, 67.0, 90.0, 95.0}) out += " " + detail::report_num(e.at(q));
    out += " " + detail::report_num(e.time_per_step_ns * 1e-3, "%10.3f") + " " +
           detail::report_num(e.sight_accuracy, "%10.3f") + "\n";
  }
  return out;
}

/// The scenario header: name, description and the numbered choices made where the paper is silent.
inline std::string format_choices(const Scenario& s) {
  std::string out = s.name() + ": " + s.description() + "\nchoices:\n";
  int i = 1;
  for (const std::string& ch : s.choices()) out += "  " + std::to_string(i++) + ". " + ch + "\n";
  if (!s.paper_source().empty()) out += "paper: " + s.paper_source() + "\n";
  return out;
}

}  // namespace nlosloc::sim
