/// \file bind_sim.cpp
/// nlosloc._core.sim: the scenario registry, draws, the Monte Carlo runner (GIL released, progress and
/// Ctrl-C handled on the calling thread), the error metrics, and the H1 / H2 scenarios with their
/// parameters (H1Params, H2Params) so that they run with custom values. K1-K3 and the K2 study are in
/// bind_sim_ke_wu.cpp, the summaries and tables in bind_sim_report.cpp.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bind.hpp"
#include "int_arg.hpp"
#include "nlosloc/sim/h1.hpp"
#include "nlosloc/sim/h2.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/registry.hpp"
#include "nlosloc/sim/report.hpp"
#include "params_field.hpp"
#include "py_estimator.hpp"

namespace py = pybind11;
namespace sim = nlosloc::sim;

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using nlosloc::bind::steps_arg;
using nlosloc::bind::UInt64Arg;

/// Copies a numpy array (any shape, flattened) into a vector.
std::vector<double> to_vector(const DoubleArray& a) {
  return std::vector<double>(a.data(), a.data() + a.size());
}

py::array_t<double> to_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// The published numbers of a scenario as a list of dicts (estimator, case, metric, value).
py::list paper_list(const sim::Scenario& s) {
  py::list paper;
  for (const sim::PaperValue& v : s.paper()) {
    py::dict d;
    d["estimator"] = v.estimator;
    d["case"] = v.case_name;
    d["metric"] = v.metric;
    d["value"] = v.value;
    paper.append(d);
  }
  return paper;
}

py::dict scenario_info(const std::string& name) {
  const sim::Registry& reg = sim::registry();
  const sim::Scenario& s = reg.scenario(name);
  const py::list paper = paper_list(s);
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

py::dict draw_dict(const sim::Scenario& s, const std::string& case_name, const UInt64Arg& seed,
                   const UInt64Arg& run, const std::optional<nlosloc::bind::StrictArg<int>>& steps) {
  return nlosloc::bind::draw_to_dict(s.draw(case_name, seed.get("seed"), run.get("run"), steps_arg(steps)));
}

py::dict draw(const std::string& name, const std::string& case_name, const UInt64Arg& seed,
              const UInt64Arg& run, const std::optional<nlosloc::bind::StrictArg<int>>& steps) {
  return draw_dict(sim::registry().scenario(name), case_name, seed, run, steps);
}

/// Runs `estimators` on `s`, which may be a scenario built with custom parameters: registered names (default
/// all registered under the scenario's name; their factories take any H1 / H2) and Python estimators
/// (py_estimator.hpp).
py::dict run_monte_carlo(const std::shared_ptr<sim::Scenario>& s, const std::string& case_name,
                         const nlosloc::bind::StrictArg<int>& runs, const UInt64Arg& seed,
                         const std::optional<py::sequence>& estimators,
                         const nlosloc::bind::StrictArg<int>& threads,
                         const std::optional<nlosloc::bind::StrictArg<int>>& steps,
                         const py::object& progress, const UInt64Arg& first_run) {
  const bool has_progress = !progress.is_none();
  if (has_progress && !PyCallable_Check(progress.ptr()))
    throw py::type_error("progress: expected a callable progress(done, total) or None");
  sim::MonteCarloOptions opt;
  opt.runs = runs.get("runs");
  opt.seed = seed.get("seed");
  opt.first_run = first_run.get("first_run");
  opt.threads = threads.get("threads");
  opt.steps = steps_arg(steps);
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
  s->case_index(case_name);  // validate before starting threads
  // Released with the GIL held: they may hold Python estimators' factories.
  const std::vector<sim::EstimatorSpec> specs =
      nlosloc::bind::estimator_specs(sim::registry(), s, estimators);
  sim::MonteCarloResult res;
  {
    py::gil_scoped_release release;
    res = sim::run_monte_carlo(*s, case_name, specs, opt);
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
  r["case_index"] = res.case_index;
  r["runs"] = res.runs;
  r["first_run"] = res.first_run;
  r["steps"] = res.steps;
  r["seed"] = res.seed;
  r["discard"] = res.discard;
  r["dt"] = res.dt;
  r["threads"] = res.threads;
  r["wall_seconds"] = res.wall_seconds;
  r["estimators"] = ests;
  return r;
}

/// The quality-statistic fields that H1Params and H2Params share (choice: Beta per condition).
template <class P, class C>
void quality_fields(C& c) {
  c.def_property("quality_los_a", nlosloc::bind::field_get<&P::quality_los_a>(),
                 nlosloc::bind::field_set<&P::quality_los_a>("quality_los_a"),
                 "Choice: o | LOS ~ Beta(a, b), a > 0.")
      .def_property("quality_los_b", nlosloc::bind::field_get<&P::quality_los_b>(),
                    nlosloc::bind::field_set<&P::quality_los_b>("quality_los_b"),
                    "Choice: o | LOS ~ Beta(a, b), b > 0.")
      .def_property("quality_nlos_a", nlosloc::bind::field_get<&P::quality_nlos_a>(),
                    nlosloc::bind::field_set<&P::quality_nlos_a>("quality_nlos_a"),
                    "Choice: o | NLOS ~ Beta(a, b), a > 0.")
      .def_property("quality_nlos_b", nlosloc::bind::field_get<&P::quality_nlos_b>(),
                    nlosloc::bind::field_set<&P::quality_nlos_b>("quality_nlos_b"),
                    "Choice: o | NLOS ~ Beta(a, b), b > 0.");
}

/// Scenario, H1Params, H1, H2Params, H2.
void bind_scenarios(py::module_& m) {
  py::class_<sim::Scenario, std::shared_ptr<sim::Scenario>>(
      m, "Scenario", "A simulation scenario: geometry, measurement stack and a draw() of truth + data.")
      .def_property_readonly("name", &sim::Scenario::name, "Short name (\"H1\").")
      .def_property_readonly("description", &sim::Scenario::description,
                             "One line with the paper and section.")
      .def_property_readonly("choices", &sim::Scenario::choices, "Values taken where the paper is silent.")
      .def_property_readonly("cases", &sim::Scenario::cases, "Case names.")
      .def_property_readonly("steps", &sim::Scenario::steps, "Default number of steps T of a run.")
      .def_property_readonly("dt", &sim::Scenario::dt, "Sampling period (s).")
      .def_property_readonly("anchors", &sim::Scenario::anchors, "(B, D) anchor positions (m).")
      .def_property_readonly("discard", &sim::Scenario::discard, "First samples left out of the statistics.")
      .def_property_readonly("state_dim", &sim::Scenario::state_dim, "Size n of the true state.")
      .def_property_readonly("space_dim", &sim::Scenario::space_dim, "Space dimension D.")
      .def_property_readonly("measurements", &sim::Scenario::measurements, py::return_value_policy::copy,
                             "The models.MeasurementStack that generates the draws' y.")
      .def_property_readonly("paper_source", &sim::Scenario::paper_source, "Where the published numbers are.")
      .def_property_readonly("paper", &paper_list,
                             "Published numbers: list of dicts estimator, case, metric, value.")
      .def("paper_value", &sim::Scenario::paper_value, py::arg("estimator"), py::arg("case"),
           py::arg("metric"),
           "The published value of `metric` (\"p67\", \"p95\", \"time_per_step_us\") for an estimator "
           "on a case, or None when the paper gives none (an unknown case is a ValueError).")
      .def("case_index", &sim::Scenario::case_index, py::arg("case"),
           "Index of a case name; ValueError listing the valid names.")
      .def("draw", &draw_dict, py::arg("case"), py::arg("seed"), py::arg("run"),
           py::arg("steps") = py::none(),
           "One realisation of a case from Rng(seed, run); the same dict as nlosloc.sim.draw().");

  using sim::H1Params;
  py::class_<H1Params> h1p(m, "H1Params",
                           "Parameters of H1 (Huerta et al. 2009 Sec. VI-A, Tables VII-VIII, plus choices). "
                           "Checked when an H1 is built from them (ValueError naming the field).");
  h1p.def(py::init<>())
      .def_property("dt", nlosloc::bind::field_get<&H1Params::dt>(),
                    nlosloc::bind::field_set<&H1Params::dt>("dt"), "Table VII: Delta t (s), > 0.")
      .def_property("steps", nlosloc::bind::field_get<&H1Params::steps>(),
                    nlosloc::bind::field_set<&H1Params::steps>("steps"),
                    "Table VII: number of steps (200 s), > discard.")
      .def_property("speed", nlosloc::bind::field_get<&H1Params::speed>(),
                    nlosloc::bind::field_set<&H1Params::speed>("speed"),
                    "Table VII: mobile speed (m/s), > 0.")
      .def_property("mean_los", nlosloc::bind::field_get<&H1Params::mean_los>(),
                    nlosloc::bind::field_set<&H1Params::mean_los>("mean_los"),
                    "Table VII: E{L_LOS} (m), > 0.")
      .def_property("mean_nlos", nlosloc::bind::field_get<&H1Params::mean_nlos>(),
                    nlosloc::bind::field_set<&H1Params::mean_nlos>("mean_nlos"),
                    "Table VII: E{L_NLOS} (m), > 0.")
      .def_property("sigma_v2", nlosloc::bind::field_get<&H1Params::sigma_v2>(),
                    nlosloc::bind::field_set<&H1Params::sigma_v2>("sigma_v2"),
                    "Table VII: filters' sigma_v^2 ((m/s)^2 per s), >= 0.")
      .def_property("toa_los_var", nlosloc::bind::field_get<&H1Params::toa_los_var>(),
                    nlosloc::bind::field_set<&H1Params::toa_los_var>("toa_los_var"),
                    "Table VIII: TOA LOS Normal variance (m^2), > 0.")
      .def_property("toa_nlos_var", nlosloc::bind::field_get<&H1Params::toa_nlos_var>(),
                    nlosloc::bind::field_set<&H1Params::toa_nlos_var>("toa_nlos_var"),
                    "Table VIII: TOA NLOS Rayleigh variance (m^2), > 0.")
      .def_property("aoa_los_var", nlosloc::bind::field_get<&H1Params::aoa_los_var>(),
                    nlosloc::bind::field_set<&H1Params::aoa_los_var>("aoa_los_var"),
                    "Table VIII: AOA LOS Normal variance (rad^2), > 0.")
      .def_property("aoa_nlos_var", nlosloc::bind::field_get<&H1Params::aoa_nlos_var>(),
                    nlosloc::bind::field_set<&H1Params::aoa_nlos_var>("aoa_nlos_var"),
                    "Table VIII: AOA NLOS Normal variance (rad^2), > 0.")
      .def_property("discard", nlosloc::bind::field_get<&H1Params::discard>(),
                    nlosloc::bind::field_set<&H1Params::discard>("discard"),
                    "Choice: first samples left out, 0 <= discard < steps.")
      .def_property("rbpf_particles", nlosloc::bind::field_get<&H1Params::rbpf_particles>(),
                    nlosloc::bind::field_set<&H1Params::rbpf_particles>("rbpf_particles"),
                    "Sec. VI-A: particles of rRBPF-8, >= 1.");
  quality_fields<H1Params>(h1p);
  nlosloc::bind::fixed_field<&H1Params::start>(h1p, "start", "H1Params.start", "Choice: start (m), (2,).");
  nlosloc::bind::fixed_field<&H1Params::heading>(h1p, "heading", "H1Params.heading",
                                                 "Choice: direction of motion, unit vector (2,).");
  nlosloc::bind::fixed_field<&H1Params::sector_deg>(h1p, "sector_deg", "H1Params.sector_deg",
                                                    "Choice: broadsides of the three sectors (deg), (3,).");
  nlosloc::bind::fixed_field<&H1Params::initial_std>(
      h1p, "initial_std", "H1Params.initial_std", "Choice: initial belief std (m, m, m/s, m/s), (4,), > 0.");

  py::class_<sim::H1, sim::Scenario, std::shared_ptr<sim::H1>>(
      m, "H1",
      "Scenario H1 (Huerta et al. 2009 Sec. VI-A): one tri-sector BS, TOA + AOA phase. Built with custom "
      "H1Params it runs with run_monte_carlo(scenario, ...) and the estimators registered for H1.")
      .def(py::init<const H1Params&>(), py::arg_v("params", H1Params(), "H1Params()"))
      .def_property_readonly(
          "params", [](const sim::H1& h) { return h.params(); }, "A copy of its H1Params.")
      .def_property_readonly("motion", &sim::H1::motion, py::return_value_policy::copy,
                             "Filters' models.ConstantVelocity2 (Huerta eqs. 6-7, random walk sigma_v^2).")
      .def_property_readonly("sight_process", &sim::H1::sight_process, py::return_value_policy::copy,
                             "The situation.SightProcess of the single anchor (eq. 17).")
      .def_property_readonly("quality", &sim::H1::quality, py::return_value_policy::copy,
                             "Quality likelihoods per condition [LOS, NLOS] (noise.Distribution).")
      .def("serving_sector", &sim::H1::serving_sector, py::arg("theta"),
           "Index (0..2) of the sector serving a mobile at bearing theta (rad).");

  using sim::H2Params;
  py::class_<H2Params> h2p(
      m, "H2Params",
      "Parameters of H2 (Huerta et al. 2009 Sec. VI-B, Tables IX-X, plus choices). Checked "
      "when an H2 is built from them (ValueError naming the field).");
  h2p.def(py::init<>())
      .def_property("side", nlosloc::bind::field_get<&H2Params::side>(),
                    nlosloc::bind::field_set<&H2Params::side>("side"),
                    "Sec. VI-B: hexagon side = circumradius (m), > 0.")
      .def_property("dt", nlosloc::bind::field_get<&H2Params::dt>(),
                    nlosloc::bind::field_set<&H2Params::dt>("dt"), "Table IX: Delta t (s), > 0.")
      .def_property("steps", nlosloc::bind::field_get<&H2Params::steps>(),
                    nlosloc::bind::field_set<&H2Params::steps>("steps"),
                    "Table IX: number of steps (60 s), > discard.")
      .def_property("sigma_v2", nlosloc::bind::field_get<&H2Params::sigma_v2>(),
                    nlosloc::bind::field_set<&H2Params::sigma_v2>("sigma_v2"),
                    "Table IX: velocity random walk sigma_v^2, >= 0.")
      .def_property("sigma_tau2", nlosloc::bind::field_get<&H2Params::sigma_tau2>(),
                    nlosloc::bind::field_set<&H2Params::sigma_tau2>("sigma_tau2"),
                    "Table IX: drift random walk sigma_tau^2, >= 0.")
      .def_property("tau0_var", nlosloc::bind::field_get<&H2Params::tau0_var>(),
                    nlosloc::bind::field_set<&H2Params::tau0_var>("tau0_var"),
                    "Table IX: E{tau_0^2} (lm^2), > 0.")
      .def_property("tau_dot0_var", nlosloc::bind::field_get<&H2Params::tau_dot0_var>(),
                    nlosloc::bind::field_set<&H2Params::tau_dot0_var>("tau_dot0_var"),
                    "Table IX: E{tau_dot_0^2} ((lm/s)^2), > 0.")
      .def_property("mean_los", nlosloc::bind::field_get<&H2Params::mean_los>(),
                    nlosloc::bind::field_set<&H2Params::mean_los>("mean_los"), "Table IX: E{L_LOS} (m), > 0.")
      .def_property("mean_nlos", nlosloc::bind::field_get<&H2Params::mean_nlos>(),
                    nlosloc::bind::field_set<&H2Params::mean_nlos>("mean_nlos"),
                    "Table IX: E{L_NLOS} (m), > 0.")
      .def_property("rtoa_los_var", nlosloc::bind::field_get<&H2Params::rtoa_los_var>(),
                    nlosloc::bind::field_set<&H2Params::rtoa_los_var>("rtoa_los_var"),
                    "Table X: RTOA LOS Normal variance, > 0.")
      .def_property("rtoa_nlos_var", nlosloc::bind::field_get<&H2Params::rtoa_nlos_var>(),
                    nlosloc::bind::field_set<&H2Params::rtoa_nlos_var>("rtoa_nlos_var"),
                    "Table X: RTOA NLOS Rayleigh variance, > 0.")
      .def_property("position0_std", nlosloc::bind::field_get<&H2Params::position0_std>(),
                    nlosloc::bind::field_set<&H2Params::position0_std>("position0_std"),
                    "Choice: std of the start (m), > 0.")
      .def_property("velocity0_std", nlosloc::bind::field_get<&H2Params::velocity0_std>(),
                    nlosloc::bind::field_set<&H2Params::velocity0_std>("velocity0_std"),
                    "Choice: std of the initial velocity, > 0.")
      .def_property("discard", nlosloc::bind::field_get<&H2Params::discard>(),
                    nlosloc::bind::field_set<&H2Params::discard>("discard"),
                    "Choice: first samples left out, 0 <= discard < steps.")
      .def_property("urr_speed", nlosloc::bind::field_get<&H2Params::urr_speed>(),
                    nlosloc::bind::field_set<&H2Params::urr_speed>("urr_speed"),
                    "Choice: transversal speed (m/s) of URR's switch probabilities, > 0.")
      .def_property("pf_particles", nlosloc::bind::field_get<&H2Params::pf_particles>(),
                    nlosloc::bind::field_set<&H2Params::pf_particles>("pf_particles"),
                    "Sec. VI-B: particles of PF, >= 1.");
  quality_fields<H2Params>(h2p);

  py::class_<sim::H2, sim::Scenario, std::shared_ptr<sim::H2>>(
      m, "H2",
      "Scenario H2 (Huerta et al. 2009 Sec. VI-B): six RTOA anchors on a hexagon, unsynchronised mobile. "
      "Built with custom H2Params it runs with run_monte_carlo(scenario, ...) and the estimators registered "
      "for H2.")
      .def(py::init<const H2Params&>(), py::arg_v("params", H2Params(), "H2Params()"))
      .def_property_readonly(
          "params", [](const sim::H2& h) { return h.params(); }, "A copy of its H2Params.")
      .def_property_readonly("motion", &sim::H2::motion, py::return_value_policy::copy,
                             "Filters' models.ConstantVelocityClock2 (Huerta eqs. 5-7).")
      .def_property_readonly("sight_process", &sim::H2::sight_process, py::return_value_policy::copy,
                             "The situation.SightProcess (one eq. 17 chain per anchor).")
      .def_property_readonly("quality", &sim::H2::quality, py::return_value_policy::copy,
                             "Quality likelihoods per condition [LOS, NLOS] (noise.Distribution).")
      .def(
          "prior_variances", [](const sim::H2& h) { return nlosloc::VecX(h.prior_variances()); },
          "(6,) diagonal of the prior covariance of x_0 = [p, tau, v, tau_dot].")
      .def("urr_switch_probability", &sim::H2::urr_switch_probability, py::arg("condition"),
           "URR's per-step probability of leaving `condition` (0 LOS, 1 NLOS), Huerta eq. (15).")
      .def("urr_nlos_span", &sim::H2::urr_nlos_span,
           "URR's uniform NLOS span W: the 99% quantile of the NLOS noise.");
}

}  // namespace

const sim::Registry& python_registry() { return sim::registry(); }

std::shared_ptr<sim::Scenario> registered_scenario(const std::string& name) {
  return std::const_pointer_cast<sim::Scenario>(sim::registry().scenario_ptr(name));
}

void bind_sim(py::module_& m) {
  bind_scenarios(m);
  bind_sim_ke_wu(m);
  bind_sim_report(m);
  bind_sim_custom(m);

  m.def(
      "scenarios", [] { return sim::registry().scenarios(); },
      R"doc(Names of the registered scenarios.

Returns
-------
list of str
    Scenario names in registration order, e.g. ``["K1"]``.
)doc");

  m.def("scenario", &registered_scenario, py::arg("name"),
        R"doc(The registered scenario object (C++ ``registry().scenario_ptr(name)``).

Parameters
----------
name : str
    Scenario name (see :func:`scenarios`).

Returns
-------
Scenario
    The object itself, of its own class (``H1``, ``H2``, ``K1``, ...): its geometry, measurement
    stack, published numbers and ``draw``; ``run_monte_carlo(scenario, ...)`` takes it.

Raises
------
ValueError
    If the scenario is unknown.
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
    ``initial_mean`` (n), ``initial_cov`` (n x n), and ``scenario``, ``case``, ``case_index`` (its
    index in ``scenario_info(name)["cases"]``), ``seed``, ``run``, ``dt``.
)doc");

  m.def(
      "run_monte_carlo",
      [](const std::string& name, const std::string& case_name, const nlosloc::bind::StrictArg<int>& runs,
         const UInt64Arg& seed, const std::optional<py::sequence>& estimators,
         const nlosloc::bind::StrictArg<int>& threads,
         const std::optional<nlosloc::bind::StrictArg<int>>& steps, const py::object& progress,
         const UInt64Arg& first_run) {
        return run_monte_carlo(registered_scenario(name), case_name, runs, seed, estimators, threads, steps,
                               progress, first_run);
      },
      py::arg("name"), py::arg("case"), py::arg("runs"), py::arg("seed"), py::arg("estimators") = py::none(),
      py::arg("threads") = 0, py::arg("steps") = py::none(), py::arg("progress") = py::none(),
      py::arg("first_run") = UInt64Arg(0),
      R"doc(Monte Carlo run of estimators, registered or written in Python, on identical draws.

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
estimators : list, optional
    Default (None): every estimator registered for the scenario; an empty list is refused
    (ValueError). Each entry is a registered name (str) or
    a pair ``(name, factory)`` of an estimator written in Python: ``factory(scenario, case_index)``
    (called once per worker thread) returns an object with ``reset(draw, rng)`` (at the start of
    each run: the draw as :func:`draw` returns it, and the estimator's own ``core.Rng``,
    ``Rng(estimator_seed(seed, name), run)``) and ``step(k, y, o)`` (step k's measurements and
    quality statistics, NaN = missing; returns the D position coordinates), and optionally
    ``sight_estimate()`` (after each step: B integer conditions, 0 = LOS; then its result has
    ``sight_accuracy``). Python estimators hold the GIL while they run, so they run one at a
    time beside the C++ ones; their ``time_per_step_ns`` includes the call overhead. An entry
    may also be ``(name, filter)`` with a filter object built for the scenario's model (its
    state size, measurement rows, anchors and dt are checked), which runs natively, without the
    GIL, as the registered estimators do: an ``Ekf``, ``Ukf`` or ``UkfAugmented`` of
    :mod:`nlosloc.filters` (a copy per worker from the draw's initial belief, updated at step 0;
    ``(name, filter, sight)`` with ``sight`` ``"assume_los"``, the default, or ``"oracle"``,
    the draw's true sight: a bound, not an estimator); an ``Iukf``, ``Rbpf`` or
    ``ParticleFilter`` of :mod:`nlosloc.rbpf` (a new filter with the given one's models and
    options per worker; a ParticleFilter's ``options.seed`` is replaced at every run by a draw
    from the estimator's own stream); a ``QpBiasEkf`` or ``BiasAugmentedEkf`` of
    :mod:`nlosloc.mitigation`; ``MleLos``, ``Chen``, ``Cong`` or ``Urruela`` of
    :mod:`nlosloc.snapshot`. Each starts every run as the registered estimator of its kind
    does (``sim/h1.hpp``, ``sim/k1.hpp``), so the same set-up gives the same numbers. The object
    given is not run or changed. A factory may return such an object too (then it runs
    natively, and ``(name, factory, sight)`` takes a sight policy for the Gaussian filters): a
    module-level factory pickles where the particle filters and the trackers do not (the
    Kalman filters and the Iukf pickle too).
threads : int, default 0
    Worker threads; 0 uses every core.
steps : int, optional
    Steps per run; default the scenario's.
progress : callable, optional
    ``progress(done, total)``, called on the calling thread (with the GIL) as runs complete.
first_run : int, default 0
    Index of the first run: the runs are ``first_run`` .. ``first_run + runs - 1``, each the same
    as in a run from 0 (row r of the result is run ``first_run + r``), so chunks run apart join
    into one result (``nlosloc.montecarlo.merge``).

Returns
-------
dict
    ``estimators``: dict name -> {``errors``: runs x T position error norms (m),
    ``time_per_step_ns``: runs, and for estimators that classify sight ``sight_accuracy``:
    (runs, T) fraction of anchors classified correctly, ``sight_anchor_accuracy``: (runs, B)};
    and ``scenario``, ``case``, ``case_index`` (its index in ``scenario_info(name)["cases"]``),
    ``runs``, ``first_run``, ``steps``, ``seed``, ``discard``, ``dt`` (s), ``threads``,
    ``wall_seconds``.

Raises
------
ValueError
    On an unknown scenario, case or estimator name, a name given twice, a bad count, or a Python
    estimator's step() or sight_estimate() result of the wrong size.
TypeError
    On an entry of ``estimators`` that is neither a name, a (name, callable) pair nor a
    (name, filter[, sight]) tuple, a sight policy with an object other than a Gaussian filter, or
    a factory result without ``reset`` and ``step``. An exception raised inside a Python estimator stops the
    run and is raised here.
)doc");

  m.def("run_monte_carlo", &run_monte_carlo, py::arg("scenario"), py::arg("case"), py::arg("runs"),
        py::arg("seed"), py::arg("estimators") = py::none(), py::arg("threads") = 0,
        py::arg("steps") = py::none(), py::arg("progress") = py::none(), py::arg("first_run") = UInt64Arg(0),
        R"doc(Monte Carlo run on a scenario object, e.g. ``H2(params)`` with custom parameters.

The same as the overload taking a name, with the estimators registered for ``scenario.name``
(their factories build each estimator from this scenario's models, so custom parameters reach them);
Python estimators' factories get this object.

Parameters
----------
scenario : Scenario
    An H1 or H2 (or any Scenario whose name is registered).
case, runs, seed, estimators, threads, steps, progress, first_run
    As in the overload taking a name.

Returns
-------
dict
    As in the overload taking a name.

Raises
------
ValueError, TypeError
    As in the overload taking a name.
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
      [](const DoubleArray& values, long long max_points) {  // signed: -1 gets a named ValueError
        NLOSLOC_ENSURE(max_points >= 0,
                       "max_points: expected 0 (all) or >= 2, got " + std::to_string(max_points));
        const sim::Ecdf e = sim::ecdf(to_vector(values), static_cast<std::size_t>(max_points));
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
      "rmse_over_time",
      [](const py::array& errors) {
        // a 1-D array would convert to (n, 1): n runs of one step, not one run of n steps
        if (errors.ndim() != 2)
          throw py::value_error("errors: expected a 2-D (runs, T) array, got " +
                                std::to_string(errors.ndim()) + "-D; one run of T steps is errors[None, :]");
        return sim::rmse_over_time(nlosloc::bind::to_matrix<sim::RowMatX>(errors, "errors"));
      },
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
