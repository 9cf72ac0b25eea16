/// \file bind_sim_ke_wu.cpp
/// nlosloc._core.sim, part 2: the Ke & Wu scenarios K1, K2, K3 with their parameters (K1Params, K2Params,
/// K3Params), so that they run with custom values through run_monte_carlo(scenario, ...), and the K2 study
/// (run_k2_study, format_k2_study) that nlosloc-bench prints for K2.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bind.hpp"
#include "int_arg.hpp"
#include "nlosloc/sim/k1.hpp"
#include "nlosloc/sim/k2.hpp"
#include "nlosloc/sim/k3.hpp"
#include "nlosloc/sim/scenario.hpp"
#include "params_field.hpp"
#include "py_estimator.hpp"

namespace py = pybind11;
namespace sim = nlosloc::sim;

namespace {

/// A case index of a scenario with `n` cases; ValueError naming `name` otherwise.
int checked_case(int c, int n, const char* name) {
  if (c < 0 || c >= n)
    throw py::value_error(std::string(name) + ": expected 0 <= " + name + " < " + std::to_string(n) +
                          ", got " + std::to_string(c));
  return c;
}
/// An anchor index in [0, n); ValueError naming `anchor` otherwise.
int checked_anchor(int b, int n) {
  if (b < 0 || b >= n)
    throw py::value_error("anchor: expected 0 <= anchor < " + std::to_string(n) + ", got " +
                          std::to_string(b));
  return b;
}

/// The fields K1Params and K3Params share (same names and meaning in both), with the struct's name in docs.
template <class P, class C>
void ke_wu_common_fields(C& c, const char* params) {
  const std::string q = params;
  c.def_property("accel_var", nlosloc::bind::field_get<&P::accel_var>(),
                 nlosloc::bind::field_set<&P::accel_var>("accel_var"),
                 "Sec. 6: sigma_x^2 = sigma_y^2 of eq. (16) ((m/s^2)^2), >= 0.")
      .def_property("steps", nlosloc::bind::field_get<&P::steps>(),
                    nlosloc::bind::field_set<&P::steps>("steps"), "Sec. 6: L, samples per run, > discard.")
      .def_property("dt", nlosloc::bind::field_get<&P::dt>(), nlosloc::bind::field_set<&P::dt>("dt"),
                    "Sec. 6: Delta t (s), > 0.")
      .def_property("discard", nlosloc::bind::field_get<&P::discard>(),
                    nlosloc::bind::field_set<&P::discard>("discard"),
                    "First samples left out of the statistics, 0 <= discard < steps.")
      .def_property("gamma", nlosloc::bind::field_get<&P::gamma>(),
                    nlosloc::bind::field_set<&P::gamma>("gamma"),
                    "Sec. 5: scaling factor of the NLOS test, eq. (32), finite >= 1.")
      .def_property("iterated_bias_prior_std", nlosloc::bind::field_get<&P::iterated_bias_prior_std>(),
                    nlosloc::bind::field_set<&P::iterated_bias_prior_std>("iterated_bias_prior_std"),
                    "Choice: iterated NLOS EKF, prior std of each bias (m), > 0.")
      .def_property("iterated_bias_walk_std", nlosloc::bind::field_get<&P::iterated_bias_walk_std>(),
                    nlosloc::bind::field_set<&P::iterated_bias_walk_std>("iterated_bias_walk_std"),
                    "Choice: iterated NLOS EKF, bias random walk (m/step), >= 0.")
      .def_property("iterated_iterations", nlosloc::bind::field_get<&P::iterated_iterations>(),
                    nlosloc::bind::field_set<&P::iterated_iterations>("iterated_iterations"),
                    "Choice: iterated NLOS EKF, iterations of the update, >= 1.");
  nlosloc::bind::fixed_field<&P::start>(c, "start", q + ".start", "Start position (m), (2,).");
  nlosloc::bind::fixed_field<&P::velocity>(c, "velocity", q + ".velocity", "Initial velocity (m/s), (2,).");
  nlosloc::bind::fixed_field<&P::initial_std>(c, "initial_std", q + ".initial_std",
                                              "Choice: initial belief std (m, m, m/s, m/s), (4,), > 0.");
}

void bind_k_scenarios(py::module_& m) {
  using sim::K1Params;
  py::class_<K1Params> k1p(
      m, "K1Params",
      "Parameters of K1 (Ke & Wu 2011 Secs. 6 and 6.1, plus choices). Checked when a K1 "
      "(or a K2 through K2Params.base) is built from them (ValueError naming the field).");
  k1p.def(py::init<>())
      .def_property("sigma_los", nlosloc::bind::field_get<&K1Params::sigma_los>(),
                    nlosloc::bind::field_set<&K1Params::sigma_los>("sigma_los"),
                    "Sec. 6: TOA noise n_i ~ N(0, sigma_los^2) (m), > 0.")
      .def_property("nlos_mean", nlosloc::bind::field_get<&K1Params::nlos_mean>(),
                    nlosloc::bind::field_set<&K1Params::nlos_mean>("nlos_mean"),
                    "Sec. 6.1: NLOS error b_i ~ N(mean, std^2) (m), > 0.")
      .def_property("nlos_std", nlosloc::bind::field_get<&K1Params::nlos_std>(),
                    nlosloc::bind::field_set<&K1Params::nlos_std>("nlos_std"),
                    "Sec. 6.1: NLOS error std (m), > 0.")
      .def_property("nlos_nonnegative", nlosloc::bind::field_get<&K1Params::nlos_nonnegative>(),
                    nlosloc::bind::field_set<&K1Params::nlos_nonnegative>("nlos_nonnegative"),
                    "Choice: b_i = max(0, draw) (Sec. 2, eq. 1: b_i(k) >= 0); False keeps the normal draw.");
  nlosloc::bind::fixed_field<&K1Params::anchors>(k1p, "anchors", "K1Params.anchors",
                                                 "Sec. 6: the three fixed nodes (m), (3, 2).");
  ke_wu_common_fields<K1Params>(k1p, "K1Params");

  py::class_<sim::K1, sim::Scenario, std::shared_ptr<sim::K1>>(
      m, "K1",
      "Scenario K1 (Ke & Wu 2011 Sec. 6.1): three TOA nodes, 0..3 of them NLOS for the whole run. Built with "
      "custom K1Params it runs with run_monte_carlo(scenario, ...) and the estimators registered for K1.")
      .def(py::init<const K1Params&>(), py::arg_v("params", K1Params(), "K1Params()"))
      .def_property_readonly(
          "params", [](const sim::K1& s) { return s.params(); }, "A copy of its K1Params.")
      .def_property_readonly("motion", &sim::K1::motion, py::return_value_policy::copy,
                             "Motion model of the truth and of the filters (Ke & Wu eq. 16).")
      .def_static(
          "nlos_count", [](int c) { return sim::K1::nlos_count(checked_case(c, 4, "case_index")); },
          py::arg("case_index"), "Number of NLOS nodes of case `case_index` (cases hold 0..3 NLOS nodes).")
      .def_static(
          "is_nlos",
          [](int c, int b) {
            return sim::K1::is_nlos(checked_case(c, 4, "case_index"), checked_anchor(b, 3));
          },
          py::arg("case_index"), py::arg("anchor"),
          "True when node `anchor` is NLOS in case `case_index` (choice: the last nlos_count nodes).");

  using sim::K2Params;
  py::class_<K2Params>(m, "K2Params",
                       "Parameters of K2 (Ke & Wu 2011 Sec. 6.2): K1's in `base` plus the switching period. "
                       "Checked when a K2 is built from them (ValueError naming the field).")
      .def(py::init<>())
      .def_property("base", nlosloc::bind::field_get<&K2Params::base>(),
                    nlosloc::bind::field_set<&K2Params::base>("base"),
                    "K1Params: geometry, noise, motion, L, dt, discard, estimator choices (edited in place).")
      .def_property("period", nlosloc::bind::field_get<&K2Params::period>(),
                    nlosloc::bind::field_set<&K2Params::period>("period"),
                    "Sec. 6.2: samples between LOS/NLOS switches, >= 1.")
      .def_property("start_nlos", nlosloc::bind::field_get<&K2Params::start_nlos>(),
                    nlosloc::bind::field_set<&K2Params::start_nlos>("start_nlos"),
                    "Choice: the first block is NLOS.");

  py::class_<sim::K2, sim::Scenario, std::shared_ptr<sim::K2>>(
      m, "K2",
      "Scenario K2 (Ke & Wu 2011 Sec. 6.2): K1's nodes and noise, every node switching between NLOS and LOS "
      "every `period` samples. Built with custom K2Params it runs with run_monte_carlo(scenario, ...).")
      .def(py::init<const K2Params&>(), py::arg_v("params", K2Params(), "K2Params()"))
      .def_property_readonly(
          "params", [](const sim::K2& s) { return s.params(); }, "A copy of its K2Params.")
      .def_property_readonly("motion", &sim::K2::motion, py::return_value_policy::copy,
                             "Motion model of the truth and of the filters (Ke & Wu eq. 16).")
      .def(
          "nlos_at",
          [](const sim::K2& s, int k) {
            if (k < 0) throw py::value_error("k: expected a sample index >= 0, got " + std::to_string(k));
            return s.nlos_at(k);
          },
          py::arg("k"), "True when the nodes are NLOS at sample k.");

  using sim::K3Params;
  py::class_<K3Params> k3p(
      m, "K3Params",
      "Parameters of K3 (Ke & Wu 2011 Sec. 6.4, plus choices). Checked when a K3 is built "
      "from them (ValueError naming the field).");
  k3p.def(py::init<>())
      .def_property("sigma_rel", nlosloc::bind::field_get<&K3Params::sigma_rel>(),
                    nlosloc::bind::field_set<&K3Params::sigma_rel>("sigma_rel"),
                    "Sec. 6.4: sigma_i = sigma_rel d_i, > 0.")
      .def_property("nlos_rel", nlosloc::bind::field_get<&K3Params::nlos_rel>(),
                    nlosloc::bind::field_set<&K3Params::nlos_rel>("nlos_rel"),
                    "Sec. 6.4: NLOS error exponential with mean nlos_rel d_i, > 0.")
      .def_property("threshold", nlosloc::bind::field_get<&K3Params::threshold>(),
                    nlosloc::bind::field_set<&K3Params::threshold>("threshold"),
                    "Sec. 6.4: error threshold (m) of P(error <= t), > 0: the bench's line, and "
                    "format_k3_probability(result, threshold).");
  nlosloc::bind::fixed_field<&K3Params::good>(k3p, "good", "K3Params.good",
                                              "Sec. 6.4: good geometry, four nodes (m), (4, 2).");
  nlosloc::bind::fixed_field<&K3Params::bad>(k3p, "bad", "K3Params.bad",
                                             "Sec. 6.4: bad geometry, four nodes (m), (4, 2).");
  ke_wu_common_fields<K3Params>(k3p, "K3Params");

  py::class_<sim::K3, sim::Scenario, std::shared_ptr<sim::K3>>(
      m, "K3",
      "Scenario K3 (Ke & Wu 2011 Sec. 6.4): four TOA nodes in a good or a bad geometry, 1..4 of them NLOS, "
      "noise relative to distance. Built with custom K3Params it runs with run_monte_carlo(scenario, ...).")
      .def(py::init<const K3Params&>(), py::arg_v("params", K3Params(), "K3Params()"))
      .def_property_readonly(
          "params", [](const sim::K3& s) { return s.params(); }, "A copy of its K3Params.")
      .def_property_readonly("motion", &sim::K3::motion, py::return_value_policy::copy,
                             "Motion model of the truth and of the filters (Ke & Wu eq. 16).")
      .def_static(
          "bad_geometry", [](int c) { return sim::K3::bad_geometry(checked_case(c, 8, "case_index")); },
          py::arg("case_index"), "True for the bad-geometry cases (indices 4..7).")
      .def_static(
          "nlos_count", [](int c) { return sim::K3::nlos_count(checked_case(c, 8, "case_index")); },
          py::arg("case_index"), "Number of NLOS nodes of case `case_index` (1..4).")
      .def_static(
          "is_nlos",
          [](int c, int b) {
            return sim::K3::is_nlos(checked_case(c, 8, "case_index"), checked_anchor(b, 4));
          },
          py::arg("case_index"), py::arg("anchor"),
          "True when node `anchor` is NLOS in case `case_index` (the last nlos_count nodes).")
      .def(
          "anchors_of",
          [](const sim::K3& s, int c) { return s.anchors_of(checked_case(c, 8, "case_index")); },
          py::arg("case_index"), "(4, 2) anchors of case `case_index` (anchors is the good geometry).");
}

void bind_k2_study(py::module_& m) {
  py::class_<sim::K2EstimatorStudy>(m, "K2EstimatorStudy", "One estimator's averages in the K2 study.")
      .def_readonly("name", &sim::K2EstimatorStudy::name)
      .def_property_readonly(
          "position_error", [](const sim::K2EstimatorStudy& e) { return e.position_error; },
          "(T,) mean over runs of ||p^_k - p_k|| (m).")
      .def_property_readonly(
          "range_error", [](const sim::K2EstimatorStudy& e) { return e.range_error; },
          "(T, B) mean over runs of | ||p^_k - a_i|| - d_i(k) | (m): Ke & Wu Fig. 3.")
      .def_property_readonly(
          "identification",
          [](const sim::K2EstimatorStudy& e) -> std::optional<nlosloc::VecX> {
            if (e.identification.size() == 0) return std::nullopt;
            return e.identification;
          },
          "(T,) fraction of (run, node) pairs whose sight was identified (Fig. 5); None for an estimator "
          "that does not classify sight.");

  py::class_<sim::K2Study>(m, "K2Study", "The K2 study: Ke & Wu Figs. 3-5 as numbers (means over runs).")
      .def_readonly("runs", &sim::K2Study::runs)
      .def_readonly("first_run", &sim::K2Study::first_run, "Index of the first run averaged.")
      .def_readonly("steps", &sim::K2Study::steps)
      .def_readonly("period", &sim::K2Study::period)
      .def_readonly("discard", &sim::K2Study::discard)
      .def_property_readonly(
          "nlos", [](const sim::K2Study& s) { return s.nlos; }, "(T,) 1 where the nodes are NLOS.")
      .def_readonly("estimators", &sim::K2Study::estimators, "One K2EstimatorStudy per estimator, in order.");

  // Both overloads: the specs (which may hold Python estimators) are made with the GIL held and the
  // study runs without it (a Python estimator takes it for each call).
  const auto study =
      [](const std::shared_ptr<sim::K2>& scenario, const nlosloc::bind::StrictArg<int>& runs,
         const nlosloc::bind::UInt64Arg& seed, const std::optional<nlosloc::bind::StrictArg<int>>& steps,
         const std::optional<py::sequence>& estimators, const nlosloc::bind::UInt64Arg& first_run) {
        const std::uint64_t s = seed.get("seed");
        const std::uint64_t f = first_run.get("first_run");
        const int t = nlosloc::bind::steps_arg(steps);
        const std::vector<sim::EstimatorSpec> specs =
            nlosloc::bind::estimator_specs(python_registry(), scenario, estimators);
        const int n = runs.get("runs");
        py::gil_scoped_release release;
        return sim::run_k2_study(*scenario, n, s, t, specs, f);
      };
  m.def(
      "run_k2_study",
      [study](const nlosloc::bind::StrictArg<int>& runs, const nlosloc::bind::UInt64Arg& seed,
              const std::optional<nlosloc::bind::StrictArg<int>>& steps,
              const std::optional<py::sequence>& estimators, const nlosloc::bind::UInt64Arg& first_run) {
        auto k2 = std::dynamic_pointer_cast<sim::K2>(registered_scenario("K2"));
        if (!k2) throw std::logic_error("run_k2_study: the registry's K2 is not a sim::K2");
        return study(k2, runs, seed, steps, estimators, first_run);
      },
      py::arg("runs"), py::arg("seed"), py::arg("steps") = py::none(), py::arg("estimators") = py::none(),
      py::kw_only(), py::arg("first_run") = nlosloc::bind::UInt64Arg(0),
      R"doc(The K2 study of Ke & Wu Sec. 6.2 (Figs. 3-5): every estimator registered for K2 (or
``estimators``) on the draws ``Rng(seed, r)``, r = ``first_run`` .. ``first_run + runs - 1``, of the
registered K2, one thread, the same draws as :func:`run_monte_carlo`; position error, ranging error
and sight identification averaged over runs.

Parameters
----------
runs : int
    Number of runs (>= 1).
seed : int
    Seed (>= 0).
steps : int, optional
    Steps per run (>= 1); default the scenario's.
estimators : list, optional
    Registered estimator names and ``(name, factory)`` pairs of estimators written in Python, as in
    :func:`run_monte_carlo`; default all registered for K2.
first_run : int, default 0
    Index of the first run (keyword only), as in :func:`run_monte_carlo`.

Returns
-------
K2Study

Raises
------
ValueError
    On a bad count, a negative seed or first_run, first_run + runs - 1 beyond 2^64 - 1, an unknown
    estimator or a name given twice.
TypeError
    On a malformed entry of ``estimators`` (see :func:`run_monte_carlo`).
)doc");
  m.def("run_k2_study", study, py::arg("scenario"), py::arg("runs"), py::arg("seed"),
        py::arg("steps") = py::none(), py::arg("estimators") = py::none(), py::kw_only(),
        py::arg("first_run") = nlosloc::bind::UInt64Arg(0),
        R"doc(The K2 study of a K2 built with custom parameters, e.g. ``K2(p)`` with another period.

The same as the overload without a scenario, on this scenario's draws; registered estimators are
built from its models, Python estimators' factories get it.

Parameters
----------
scenario : K2
    The scenario.
runs, seed, steps, estimators, first_run
    As in the overload without a scenario.

Returns
-------
K2Study

Raises
------
ValueError, TypeError
    As in the overload without a scenario.
)doc");

  m.def("format_k2_study", &sim::format_k2_study, py::arg("study"),
        "The K2 study as text (what nlosloc-bench prints): per estimator, position and ranging errors in "
        "NLOS and LOS blocks, identification overall, per sight, near the switches and elsewhere.");
}

}  // namespace

void bind_sim_ke_wu(py::module_& m) {
  bind_k_scenarios(m);
  bind_k2_study(m);
}
