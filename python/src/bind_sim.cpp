/// \file bind_sim.cpp
/// nlosloc._core.sim: the scenario registry, draws, the Monte Carlo runner (GIL released, progress and
/// Ctrl-C handled on the calling thread) and the error metrics.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bind.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/registry.hpp"
#include "nlosloc/sim/report.hpp"

namespace py = pybind11;
namespace sim = nlosloc::sim;

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Copies a numpy array (any shape, flattened) into a vector.
std::vector<double> to_vector(const DoubleArray& a) {
  return std::vector<double>(a.data(), a.data() + a.size());
}

py::array_t<double> to_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::dict scenario_info(const std::string& name) {
  const sim::Registry& reg = sim::registry();
  const sim::Scenario& s = reg.scenario(name);
  py::list paper;
  for (const sim::PaperValue& v : s.paper()) {
    py::dict d;
    d["estimator"] = v.estimator;
    d["case"] = v.case_name;
    d["metric"] = v.metric;
    d["value"] = v.value;
    paper.append(d);
  }
  py::dict info;
  info["name"] = s.name();
  info["description"] = s.description();
  info["choices"] = s.choices();
  info["cases"] = s.cases();
  info["estimators"] = reg.estimators(name);
  info["steps"] = s.steps();
  info["dt"] = s.dt();
  info["discard"] = s.discard();
  info["state_dim"] = s.state_dim();
  info["anchors"] = py::cast(s.anchors());
  info["paper_source"] = s.paper_source();
  info["paper"] = paper;
  return info;
}

py::dict draw(const std::string& name, const std::string& case_name, std::uint64_t seed, std::uint64_t run,
              std::optional<int> steps) {
  sim::Draw d = sim::registry().scenario(name).draw(case_name, seed, run, steps.value_or(0));
  py::dict r;
  r["scenario"] = d.scenario;
  r["case"] = d.case_name;
  r["seed"] = d.seed;
  r["run"] = d.run;
  r["dt"] = d.dt;
  r["states"] = py::cast(std::move(d.states));
  r["positions"] = py::cast(std::move(d.positions));
  r["y"] = py::cast(std::move(d.y));
  r["sight"] = py::cast(std::move(d.sight));
  r["quality"] = py::cast(std::move(d.quality));
  r["initial_mean"] = py::cast(std::move(d.initial_mean));
  r["initial_cov"] = py::cast(std::move(d.initial_cov));
  return r;
}

py::dict run_monte_carlo(const std::string& name, const std::string& case_name, int runs, std::uint64_t seed,
                         std::optional<std::vector<std::string>> estimators, int threads,
                         std::optional<int> steps, const py::object& progress) {
  const bool has_progress = !progress.is_none();
  if (has_progress && !PyCallable_Check(progress.ptr()))
    throw py::type_error("progress: expected a callable progress(done, total) or None");
  sim::MonteCarloOptions opt;
  opt.runs = runs;
  opt.seed = seed;
  opt.threads = threads;
  opt.steps = steps.value_or(0);
  // Both callbacks run on this (the calling) thread and take the GIL only while they call into Python;
  // they capture `progress` by reference, so copying them never touches reference counts without the GIL.
  if (has_progress)
    opt.progress = [&progress](int done, int total) {
      py::gil_scoped_acquire gil;
      progress(done, total);
    };
  opt.poll = [] {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C cancels the run
  };
  const std::vector<std::string> names = estimators.value_or(std::vector<std::string>{});
  sim::MonteCarloResult res;
  {
    py::gil_scoped_release release;
    res = sim::run_monte_carlo(sim::registry(), name, case_name, names, opt);
  }
  py::dict ests;
  for (sim::EstimatorRuns& e : res.estimators) {
    py::dict d;
    d["errors"] = py::cast(std::move(e.errors));
    d["time_per_step_ns"] = py::cast(std::move(e.time_per_step_ns));
    if (e.sight_accuracy.size() > 0) {  // estimators that classify sight (Estimator::estimates_sight)
      d["sight_accuracy"] = py::cast(std::move(e.sight_accuracy));
      d["sight_anchor_accuracy"] = py::cast(std::move(e.sight_anchor_accuracy));
    }
    ests[py::str(e.name)] = d;
  }
  py::dict r;
  r["scenario"] = res.scenario;
  r["case"] = res.case_name;
  r["runs"] = res.runs;
  r["steps"] = res.steps;
  r["seed"] = res.seed;
  r["discard"] = res.discard;
  r["dt"] = res.dt;
  r["threads"] = res.threads;
  r["wall_seconds"] = res.wall_seconds;
  r["estimators"] = ests;
  return r;
}

}  // namespace

void bind_sim(py::module_& m) {
  m.def(
      "scenarios", [] { return sim::registry().scenarios(); },
      R"doc(Names of the registered scenarios.

Returns
-------
list of str
    Scenario names in registration order, e.g. ``["K1"]``.
)doc");

  m.def("scenario_info", &scenario_info, py::arg("name"),
        R"doc(Description of a scenario.

Parameters
----------
name : str
    Scenario name (see :func:`scenarios`).

Returns
-------
dict
    ``name``, ``description``, ``choices`` (list of str: values taken where the paper is silent),
    ``cases`` (list of str), ``estimators`` (registered names), ``steps``, ``dt`` (s), ``discard``
    (first samples left out of the statistics), ``state_dim``, ``anchors`` (B x D, m),
    ``paper_source`` and ``paper`` (list of dicts ``estimator``, ``case``, ``metric``, ``value``: the
    published numbers, for every estimator the paper reports).

Raises
------
ValueError
    If the scenario is unknown.
)doc");

  m.def("draw", &draw, py::arg("name"), py::arg("case"), py::arg("seed"), py::arg("run"),
        py::arg("steps") = py::none(),
        R"doc(One realisation of a scenario case, generated from ``Rng(seed, run)``.

Parameters
----------
name : str
    Scenario name.
case : str
    Case name (see ``scenario_info(name)["cases"]``).
seed : int
    Seed (>= 0).
run : int
    Run index (the generator's stream).
steps : int, optional
    Number of steps T; default the scenario's. A shorter draw is a prefix of a longer one.

Returns
-------
dict
    ``states`` (T x n), ``positions`` (T x D, m), ``y`` (T x m measurements, NaN = missing),
    ``sight`` (T x B int, 0 = LOS), ``quality`` (T x B, NaN when the scenario has none),
    ``initial_mean`` (n), ``initial_cov`` (n x n), and ``scenario``, ``case``, ``seed``, ``run``, ``dt``.
)doc");

  m.def("run_monte_carlo", &run_monte_carlo, py::arg("name"), py::arg("case"), py::arg("runs"),
        py::arg("seed"), py::arg("estimators") = py::none(), py::arg("threads") = 0,
        py::arg("steps") = py::none(), py::arg("progress") = py::none(),
        R"doc(Monte Carlo run of registered estimators on identical draws.

Every run's draw is generated once and fed to every estimator; the result does not depend on
``threads``. The GIL is released while the workers run; Ctrl-C cancels.

Parameters
----------
name : str
    Scenario name.
case : str
    Case name.
runs : int
    Number of runs (>= 1).
seed : int
    Seed; run r draws from ``Rng(seed, r)``.
estimators : list of str, optional
    Estimator names; default all registered for the scenario.
threads : int, default 0
    Worker threads; 0 uses every core.
steps : int, optional
    Steps per run; default the scenario's.
progress : callable, optional
    ``progress(done, total)``, called on the calling thread (with the GIL) as runs complete.

Returns
-------
dict
    ``estimators``: dict name -> {``errors``: runs x T position error norms (m),
    ``time_per_step_ns``: runs, and for estimators that classify sight ``sight_accuracy``:
    (runs, T) fraction of anchors classified correctly, ``sight_anchor_accuracy``: (runs, B)}; and ``scenario``, ``case``, ``runs``, ``steps``, ``seed``,
    ``discard``, ``dt`` (s), ``threads``, ``wall_seconds``.

Raises
------
ValueError
    On an unknown scenario, case or estimator name, or a bad count.
)doc");

  m.def(
      "percentiles",
      [](const DoubleArray& values, const DoubleArray& q) {
        return to_array(sim::percentiles(to_vector(values), to_vector(q)));
      },
      py::arg("values"), py::arg("q"),
      R"doc(Percentiles by linear interpolation (numpy.percentile's default method).

Parameters
----------
values : array_like
    Values (flattened).
q : array_like
    Percentage levels in [0, 100].

Returns
-------
numpy.ndarray
    One percentile per level; NaN if values is empty or holds a NaN.
)doc");

  m.def(
      "ecdf",
      [](const DoubleArray& values, std::size_t max_points) {
        const sim::Ecdf e = sim::ecdf(to_vector(values), max_points);
        return py::make_tuple(to_array(e.x), to_array(e.p));
      },
      py::arg("values"), py::arg("max_points") = 0,
      R"doc(Empirical CDF.

Parameters
----------
values : array_like
    Values (flattened).
max_points : int, default 0
    Keep at most this many points, evenly spaced in rank (0 keeps all).

Returns
-------
tuple of numpy.ndarray
    ``(x, p)``: x ascending and ``p[i] = rank(x[i]) / n``.
)doc");

  m.def(
      "rmse_over_time", [](const sim::RowMatX& errors) { return sim::rmse_over_time(errors); },
      py::arg("errors"),
      R"doc(Root mean square error at each step across runs (Ke & Wu 2011 Sec. 6.1).

Parameters
----------
errors : numpy.ndarray
    runs x T position error norms (m).

Returns
-------
numpy.ndarray
    T values ``sqrt(mean over runs of errors**2)``.
)doc");

  m.def(
      "probability_within",
      [](const DoubleArray& values, double threshold) {
        return sim::probability_within(to_vector(values), threshold);
      },
      py::arg("values"), py::arg("threshold"),
      R"doc(Fraction of values at most ``threshold`` (Ke & Wu 2011 Sec. 6.4).

Parameters
----------
values : array_like
    Values (flattened); NaN counts as above the threshold.
threshold : float
    Threshold (same unit as values).

Returns
-------
float
    The fraction, NaN for an empty input.
)doc");
}
