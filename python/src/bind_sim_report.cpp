/// \file bind_sim_report.cpp
/// nlosloc._core.sim, part 3: the summaries and text tables of report.hpp (summarize, format_table,
/// format_percentile_table, format_choices, format_k3_probability), estimator_seed, percentile and
/// default_levels. They take the dict that run_monte_carlo returns, read back into a MonteCarloResult
/// with every key and shape checked, so a dict edited or built by hand gets a ValueError naming the entry.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "bind.hpp"
#include "int_arg.hpp"
#include "nlosloc/sim/k3.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/report.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace py = pybind11;
namespace sim = nlosloc::sim;

namespace {

/// d[key], or ValueError naming where (`where`['key']) it is missing.
py::object item(const py::dict& d, const char* key, const std::string& where) {
  if (!d.contains(key))
    throw py::value_error(where + ": expected the dict of run_monte_carlo, missing key '" + key + "'");
  return d[key];
}

/// d[key] cast to T, or ValueError naming the entry and the expected type.
template <class T>
T typed_item(const py::dict& d, const char* key, const std::string& where, const char* expected) {
  py::object v = item(d, key, where);
  const std::string name = where + "['" + key + "']";
  if constexpr (std::is_same_v<T, nlosloc::VecX>) {
    return nlosloc::bind::to_vector(v, name.c_str());  // bool, complex or str arrays refused, named
  } else if constexpr (std::is_same_v<T, sim::RowMatX>) {
    return nlosloc::bind::to_matrix<sim::RowMatX>(v, name.c_str());
  } else {
    try {
      return v.cast<T>();
    } catch (const py::cast_error&) {
      throw py::value_error(name + ": expected " + expected + ", got " +
                            std::string(py::str(py::type::of(v).attr("__name__"))));
    }
  }
}

/// A (rows, cols) float array entry; ValueError naming it when the shape differs (cols < 0: any).
sim::RowMatX matrix_item(const py::dict& d, const char* key, const std::string& where, Eigen::Index rows,
                         Eigen::Index cols) {
  const std::string name = where + "['" + key + "']";
  auto m = typed_item<sim::RowMatX>(d, key, where, "a 2-D float array");
  nlosloc::detail::ensure_shape(m, rows, cols, name.c_str());
  return m;
}

/// The dict of run_monte_carlo back as the C++ result.
sim::MonteCarloResult result_from_dict(const py::dict& d, const sim::Scenario* scenario) {
  const std::string w = "result";
  sim::MonteCarloResult r;
  r.scenario = typed_item<std::string>(d, "scenario", w, "str");
  r.case_name = typed_item<std::string>(d, "case", w, "str");
  r.runs = typed_item<int>(d, "runs", w, "int");
  // optional: a result dict written by hand, or before first_run existed, starts at run 0
  if (d.contains("first_run")) r.first_run = typed_item<std::uint64_t>(d, "first_run", w, "an int >= 0");
  r.steps = typed_item<int>(d, "steps", w, "int");
  r.discard = typed_item<int>(d, "discard", w, "int");
  r.threads = typed_item<int>(d, "threads", w, "int");
  r.seed = typed_item<std::uint64_t>(d, "seed", w, "an int >= 0");
  r.dt = typed_item<double>(d, "dt", w, "float");
  r.wall_seconds = typed_item<double>(d, "wall_seconds", w, "float");
  if (r.runs < 1 || r.steps < 1 || r.discard < 0 || r.discard >= r.steps)
    throw py::value_error("result: expected runs >= 1 and 0 <= discard < steps, got runs " +
                          std::to_string(r.runs) + ", steps " + std::to_string(r.steps) + ", discard " +
                          std::to_string(r.discard));
  if (scenario != nullptr) {
    if (r.scenario != scenario->name())
      throw py::value_error("result: is a run of scenario '" + r.scenario + "', not of '" + scenario->name() +
                            "'");
    r.case_index = scenario->case_index(r.case_name);
  }
  const auto ests = typed_item<py::dict>(d, "estimators", w, "a dict name -> dict");
  for (const auto& kv : ests) {
    sim::EstimatorRuns e;
    e.name = py::str(kv.first);
    const std::string we = w + "['estimators']['" + e.name + "']";
    if (!py::isinstance<py::dict>(kv.second)) throw py::value_error(we + ": expected a dict");
    const auto ed = py::reinterpret_borrow<py::dict>(kv.second);
    e.errors = matrix_item(ed, "errors", we, r.runs, r.steps);
    const auto t = typed_item<nlosloc::VecX>(ed, "time_per_step_ns", we, "a 1-D float array");
    nlosloc::detail::ensure_shape(t, r.runs, 1, (we + "['time_per_step_ns']").c_str());
    e.time_per_step_ns = t;
    if (ed.contains("sight_accuracy") || ed.contains("sight_anchor_accuracy")) {
      e.sight_accuracy = matrix_item(ed, "sight_accuracy", we, r.runs, r.steps);
      e.sight_anchor_accuracy = matrix_item(ed, "sight_anchor_accuracy", we, r.runs, -1);
    }
    r.estimators.push_back(std::move(e));
  }
  return r;
}

const sim::Scenario& scenario_named(const std::string& name) { return python_registry().scenario(name); }

sim::CaseSummary summarize(const sim::Scenario& s, const py::dict& result,
                           const std::optional<std::vector<double>>& levels) {
  const std::vector<double> lv = levels.value_or(sim::default_levels());
  for (double q : lv)
    if (!(q >= 0.0 && q <= 100.0))
      throw py::value_error("levels: expected percentage levels in [0, 100], got " + std::to_string(q));
  return sim::summarize(s, result_from_dict(result, &s), lv);
}

constexpr const char* kSummarizeDoc = R"doc(Percentiles of the position error pooled over runs and steps
k >= discard, the mean time per step and the paper's published values, per estimator (what
nlosloc-bench tabulates).

Parameters
----------
scenario : Scenario or str
    The scenario the result was run on (an object, e.g. ``H2(params)``, or a registered name).
result : dict
    The dict returned by :func:`run_monte_carlo`.
levels : list of float, optional
    Percentage levels in [0, 100]; default :func:`default_levels` (50, 67, 90, 95).

Returns
-------
CaseSummary

Raises
------
ValueError
    If ``result`` is not a run of ``scenario``, misses a key, or an array has the wrong shape.
)doc";

}  // namespace

void bind_sim_report(py::module_& m) {
  py::class_<sim::EstimatorSummary>(m, "EstimatorSummary", "Summary of one estimator on one case.")
      .def_readonly("name", &sim::EstimatorSummary::name)
      .def_readonly("levels", &sim::EstimatorSummary::levels, "Percentile levels (%).")
      .def_readonly("percentiles", &sim::EstimatorSummary::percentiles,
                    "Position error (m) at each level, pooled over runs and steps k >= discard.")
      .def_readonly("time_per_step_ns", &sim::EstimatorSummary::time_per_step_ns,
                    "Mean over runs of the time per step (ns).")
      .def_readonly("paper_p67", &sim::EstimatorSummary::paper_p67, "Published 67% error (m), or None.")
      .def_readonly("paper_p95", &sim::EstimatorSummary::paper_p95, "Published 95% error (m), or None.")
      .def_readonly("paper_time_per_step_us", &sim::EstimatorSummary::paper_time_per_step_us,
                    "Published time per step (us), or None.")
      .def_readonly("sight_accuracy", &sim::EstimatorSummary::sight_accuracy,
                    "Fraction of (anchor, step k >= discard) pairs classified correctly; None for an "
                    "estimator that does not classify sight.")
      .def("at", &sim::EstimatorSummary::at, py::arg("level"),
           "Percentile at `level` (one of levels); NaN if it was not computed.");

  py::class_<sim::CaseSummary>(m, "CaseSummary", "Summary of one case: one EstimatorSummary per estimator.")
      .def_readonly("scenario", &sim::CaseSummary::scenario)
      .def_readonly("case", &sim::CaseSummary::case_name)
      .def_readonly("runs", &sim::CaseSummary::runs)
      .def_readonly("first_run", &sim::CaseSummary::first_run, "Index of the first run summarised.")
      .def_readonly("steps", &sim::CaseSummary::steps)
      .def_readonly("discard", &sim::CaseSummary::discard)
      .def_readonly("wall_seconds", &sim::CaseSummary::wall_seconds)
      .def_readonly("estimators", &sim::CaseSummary::estimators, "In the result's order.");

  m.def("default_levels", &sim::default_levels, "Percentile levels reported by default: [50, 67, 90, 95].");

  m.def("summarize", &summarize, py::arg("scenario"), py::arg("result"), py::arg("levels") = py::none(),
        kSummarizeDoc);
  m.def(
      "summarize",
      [](const std::string& name, const py::dict& result, const std::optional<std::vector<double>>& levels) {
        return summarize(scenario_named(name), result, levels);
      },
      py::arg("scenario"), py::arg("result"), py::arg("levels") = py::none(), kSummarizeDoc);

  m.def(
      "format_table", &sim::format_table, py::arg("summary"),
      "The case table nlosloc-bench prints: ours and the paper's 67% / 95% errors, their ratios, time per "
      "step and sight accuracy; format_percentile_table's when the paper publishes no number for the case.");
  m.def("format_percentile_table", &sim::format_percentile_table, py::arg("summary"),
        "The case table without paper columns: 50 / 67 / 90 / 95% errors, time per step, sight accuracy.");
  m.def("format_choices", &sim::format_choices, py::arg("scenario"),
        "The scenario header: name, description, the numbered choices made where the paper is silent, and "
        "where the published numbers are.");
  m.def(
      "format_choices", [](const std::string& name) { return sim::format_choices(scenario_named(name)); },
      py::arg("scenario"), "The same, for a registered scenario name.");
  m.def(
      "format_k3_probability",
      [](const py::dict& result, double threshold) {
        if (!(threshold > 0.0) || !std::isfinite(threshold))
          throw py::value_error("threshold: expected a finite value > 0 (m), got " +
                                std::to_string(threshold));
        return sim::format_k3_probability(result_from_dict(result, nullptr), threshold);
      },
      py::arg("result"), py::arg("threshold") = 5.0,
      "One line per estimator: P(position error <= threshold) pooled over runs and steps k >= discard "
      "(Ke & Wu Sec. 6.4, Figs. 6-7), from a run_monte_carlo result.");

  m.def(
      "estimator_seed",
      [](const nlosloc::bind::UInt64Arg& seed, const std::string& name) {
        return sim::estimator_seed(seed.get("seed"), name);
      },
      py::arg("seed"), py::arg("name"),
      "Seed of estimator `name`'s generator in a Monte Carlo run with `seed`: run r uses "
      "Rng(estimator_seed(seed, name), r), the same whatever other estimators run beside it.");

  m.def(
      "percentile",
      [](const py::array_t<double, py::array::c_style | py::array::forcecast>& values, double q) {
        return sim::percentile(std::vector<double>(values.data(), values.data() + values.size()), q);
      },
      py::arg("values"), py::arg("q"),
      "The q-th percentile (q in [0, 100]) of `values` (flattened), numpy.percentile's default definition; "
      "NaN if values is empty or holds a NaN.");
}
