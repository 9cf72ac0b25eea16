/// \file bind_situation.cpp
/// nlosloc.situation: sight Markov models (Huerta eqs. 9-18, Grisales eq. 16), quality-statistic
/// likelihoods and the per-anchor forward filter (Huerta eqs. 35-38).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <string>

#include "bind.hpp"
#include "field_value.hpp"
#include "motion_arg.hpp"
#include "nlosloc/situation/forward.hpp"
#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_situation_cpp {
using namespace nlosloc::situation;

void define_module(py::module_& m) {
  py::enum_<SpeedModel>(m, "SpeedModel", "Form of the speed-dependent two-state chain.")
      .value("Single", SpeedModel::kSingle, "Huerta eq. (15): at most one change per interval")
      .value("Multiple", SpeedModel::kMultiple, "Huerta eq. (17): any number of changes per interval")
      .value("Memoryless", SpeedModel::kMemoryless, "Huerta eq. (18): rows (p_L, p_N)");

  m.def(
      "transversal_speed",
      [](const bind::VecArg& p_in, const bind::VecArg& v_in, const bind::VecArg& q_in) {
        const VecX p = p_in.get("p");
        const VecX v = v_in.get("v");
        const VecX q = q_in.get("q");
        NLOSLOC_ENSURE(p.size() == v.size() && p.size() == q.size(),
                       "p, v, q: expected vectors of the same size");
        nlosloc::detail::ensure_finite(p, "p");
        nlosloc::detail::ensure_finite(v, "v");
        nlosloc::detail::ensure_finite(q, "q");
        return transversal_speed(p, v, q);
      },
      py::arg("p"), py::arg("v"), py::arg("q"),
      "Transversal speed of a mobile at p with velocity v w.r.t. an anchor at q (Huerta eq. 10), m/s.");
  m.def(
      "transversal_speeds",
      [](const bind::VecArg& p_in, const bind::VecArg& v_in, const bind::MatArg& anchors_in) {
        const VecX p = p_in.get("p");
        const VecX v = v_in.get("v");
        const MatX anchors = anchors_in.get("anchors");
        NLOSLOC_ENSURE(p.size() == v.size(), "p, v: expected vectors of the same size");
        nlosloc::detail::ensure_shape(anchors, -1, p.size(), "anchors");
        nlosloc::detail::ensure_finite(p, "p");
        nlosloc::detail::ensure_finite(v, "v");
        nlosloc::detail::ensure_finite(anchors, "anchors");
        VecX out(anchors.rows());
        transversal_speeds(p, v, anchors, out);
        return out;
      },
      py::arg("p"), py::arg("v"), py::arg("anchors"),
      "Transversal speed (Huerta eq. 10) w.r.t. every anchor (rows of anchors (B, D)), shape (B,).");
  m.def("speed_transition_single",
        bind::strict_fn(&speed_transition_single, "w", "dt", "mean_los", "mean_nlos"), py::arg("w"),
        py::arg("dt"), py::arg("mean_los"), py::arg("mean_nlos"),
        "2x2 [LOS, NLOS] transition matrix of Huerta eq. (15).");
  m.def("speed_transition_multiple",
        bind::strict_fn(&speed_transition_multiple, "w", "dt", "mean_los", "mean_nlos"), py::arg("w"),
        py::arg("dt"), py::arg("mean_los"), py::arg("mean_nlos"),
        "2x2 transition matrix of Huerta eq. (17).");
  m.def("speed_transition_memoryless", bind::strict_fn(&speed_transition_memoryless, "mean_los", "mean_nlos"),
        py::arg("mean_los"), py::arg("mean_nlos"),
        "2x2 memoryless matrix of Huerta eq. (18), rows (p_L, p_N).");

  py::class_<SightModel>(m, "SightModel",
                         "Sight chain of one anchor: fixed N_z x N_z or speed-dependent LOS/NLOS.")
      .def_static(
          "fixed", bind::strict_fn(&SightModel::fixed, "transition", "k_sight", "initial"),
          py::arg("transition"), py::arg("k_sight") = 1, py::arg("initial") = VecX(),
          "Fixed row-stochastic matrix (N_z, N_z); changes only every k_sight steps (Grisales eq. 16). "
          "initial (N_z,) prior of s_0, empty: stationary distribution.")
      .def_static(
          "speed_dependent",
          bind::strict_fn(&SightModel::speed_dependent, "mean_los", "mean_nlos", "dt", "form", "initial"),
          py::arg("mean_los"), py::arg("mean_nlos"), py::arg("dt"), py::arg("form") = SpeedModel::kMultiple,
          py::arg("initial") = VecX(),
          "LOS/NLOS chain from the transversal speed (Huerta eqs. 14-18); mean lengths in m, dt in s.")
      .def_property_readonly("num_conditions", &SightModel::num_conditions)
      .def_property_readonly("is_speed_dependent",
                             static_cast<bool (SightModel::*)() const>(&SightModel::speed_dependent))
      .def_property_readonly("k_sight", &SightModel::k_sight)
      .def_property_readonly("base_matrix", &SightModel::base_matrix, py::return_value_policy::copy)
      .def_property_readonly("initial", &SightModel::initial, py::return_value_policy::copy)
      .def_property_readonly("mean_los", &SightModel::mean_los, "Mean LOS length (m); 0 for a fixed chain.")
      .def_property_readonly("mean_nlos", &SightModel::mean_nlos,
                             "Mean NLOS length (m); 0 for a fixed chain.")
      .def_property_readonly("dt", &SightModel::dt,
                             "Interval (s) of a speed-dependent chain; 0 for a fixed one.")
      .def_property_readonly("form", &SightModel::form, "Form of a speed-dependent chain.")
      .def("is_change_step", &SightModel::is_change_step, py::arg("k"))
      .def(
          "transition", [](const SightModel& s, long k, double w) { return s.transition(k, w); },
          py::arg("k"), py::arg("w") = 0.0,
          "Transition matrix of the step k-1 -> k at transversal speed w (m/s).")
      .def("sample_next", &SightModel::sample_next, py::arg("current"), py::arg("k"), py::arg("w"),
           py::arg("rng"), "Draws s_k given s_{k-1} = current.")
      .def("sample_initial", &SightModel::sample_initial, py::arg("rng"));

  m.def(
      "speed_switch_probability",
      [](const SightModel& model, int current, double w) {
        NLOSLOC_ENSURE(model.speed_dependent(), "model: expected a speed-dependent chain");
        NLOSLOC_ENSURE(current == 0 || current == 1,
                       "current: expected 0 (LOS) or 1 (NLOS), got " + std::to_string(current));
        nlosloc::detail::ensure_nonnegative(w, "w");
        return speed_switch_probability(model, current, w);
      },
      py::arg("model"), py::arg("current"), py::arg("w"),
      "Probability that a speed-dependent chain leaves `current` in one interval at transversal speed w "
      "(the off-diagonal entry of eq. 15, 17 or 18, in closed form).");

  py::class_<SightProcess>(m, "SightProcess", "Independent sight chains of B anchors (Huerta eq. 9).")
      .def(py::init<std::vector<SightModel>>(), py::arg("models"))
      .def(bind::strict_init<SightProcess, SightModel, int>("model", "num_anchors"), py::arg("model"),
           py::arg("num_anchors"))
      .def_property_readonly("num_anchors", &SightProcess::num_anchors)
      .def_property_readonly("num_conditions", &SightProcess::num_conditions)
      .def_property_readonly("is_speed_dependent", &SightProcess::speed_dependent)
      .def("model", &SightProcess::model, py::arg("b"))
      .def("sample_initial", &SightProcess::sample_initial, py::arg("rng"))
      .def(
          "sample_next",
          [](const SightProcess& p, const bind::StrictArg<VecXi>& current, long k, const bind::VecArg& speeds,
             Rng& rng) { return p.sample_next(current.get("current"), k, speeds.get("speeds"), rng); },
          py::arg("current"), py::arg("k"), py::arg("speeds"), py::arg("rng"),
          "Draws s_k (B,) from s_{k-1}; speeds (B,) transversal speeds (may be empty if unused).")
      .def(
          "log_transition",
          [](const SightProcess& p, const bind::StrictArg<VecXi>& from, const bind::StrictArg<VecXi>& to,
             long k, const bind::VecArg& speeds) {
            return p.log_transition(from.get("from"), to.get("to"), k, speeds.get("speeds"));
          },
          py::arg("from"), py::arg("to"), py::arg("k"), py::arg("speeds"),
          "log p(s_k = to | s_{k-1} = from), eq. (9).");

  py::class_<QualityModel>(m, "QualityModel",
                           "Quality-statistic likelihoods p(o | s = z), one distribution per z.")
      .def(py::init<std::vector<noise::Distribution>>(), py::arg("per_condition"))
      .def_property_readonly("num_conditions", &QualityModel::num_conditions)
      .def("distribution", &QualityModel::distribution, py::arg("z"))
      .def(
          "log_likelihood", [](const QualityModel& q, double o, int z) { return q.log_likelihood(o, z); },
          py::arg("o"), py::arg("z"), "log p(o | s = z); 0 for NaN (missing).")
      .def(
          "log_likelihood",
          [](const QualityModel& q, const bind::VecArg& o_in, const py::object& s) {
            const VecX o = o_in.get("o");
            return q.log_likelihood(o, bind::to_sight(s, "s"));
          },
          py::arg("o"), py::arg("s"), "log p(o | s) = sum_b log p(o_b | s_b) for o (B,) and s (B,).")
      .def(
          "log_likelihoods",
          [](const QualityModel& q, double o) {
            VecX out(q.num_conditions());
            q.log_likelihoods(o, out);
            return out;
          },
          py::arg("o"), "log p(o | s = z) for every z, shape (N_z,).")
      .def(
          "log_likelihood_table",
          [](const QualityModel& q, const bind::VecArg& o_in) {
            const VecX o = o_in.get("o");
            MatX out;
            q.log_likelihood_table(o, out);
            return out;
          },
          py::arg("o"), "(B, N_z) table of log p(o_b | s_b = z).")
      .def(
          "sample",
          [](const QualityModel& q, int z, Rng& rng) { return q.sample(z, rng); },  // z checked there
          py::arg("z"), py::arg("rng"), "One statistic drawn under condition z (simulation).")
      .def(
          "sample",
          [](const QualityModel& q, const py::object& s, Rng& rng) {
            return q.sample(bind::to_sight(s, "s"), rng);
          },
          py::arg("s"), py::arg("rng"), "One statistic per anchor for situation s (B,).");

  py::class_<ForwardFilter::Snapshot>(m, "ForwardFilterSnapshot", "State saved by ForwardFilter.save().")
      .def(py::init([](const bind::MatArg& gamma_in, const bind::MatArg& pred_in,
                       const bind::StrictArg<long>& k_in, const bind::StrictArg<double>& log_evidence_in) {
             const MatX gamma = gamma_in.get("gamma");
             const MatX pred = pred_in.get("pred");
             const long k = k_in.get("k");
             const double log_evidence = log_evidence_in.get("log_evidence");
             NLOSLOC_ENSURE(gamma.rows() >= 1 && gamma.cols() >= 1, "gamma: expected a (B, N_z) array");
             // The checks of ForwardFilter::restore (forward.hpp), without a filter to take B and N_z
             // from.
             check_probabilities(gamma, gamma.rows(), gamma.cols(), "gamma");
             check_probabilities(pred, gamma.rows(), gamma.cols(), "pred");
             NLOSLOC_ENSURE(k >= 0, "k: expected a step index >= 0, got " + std::to_string(k));
             NLOSLOC_ENSURE(std::isfinite(log_evidence), "log_evidence: expected a finite value, got " +
                                                             nlosloc::detail::fmt_shortest(log_evidence));
             return ForwardFilter::Snapshot{gamma, pred, k, log_evidence};
           }),
           py::arg("gamma"), py::arg("pred"), py::arg("k"), py::arg("log_evidence"),
           "A state to restore(): gamma and pred (B, N_z) rows of probabilities (>= 0, summing to 1), step "
           "index k >= 0, last log evidence (restore() checks the shapes against the filter).")
      .def_readonly("gamma", &ForwardFilter::Snapshot::gamma, "(B, N_z) probabilities.")
      .def_readonly("pred", &ForwardFilter::Snapshot::pred, "(B, N_z) predicted probabilities.")
      .def_readonly("k", &ForwardFilter::Snapshot::k, "Step index.")
      .def_readonly("log_evidence", &ForwardFilter::Snapshot::log_evidence, "Last log evidence.");
  py::class_<ForwardFilter>(m, "ForwardFilter",
                            "Per-anchor HMM forward filter of the sight (Huerta eqs. 35-38).")
      .def(py::init<SightProcess, QualityModel>(), py::arg("process"), py::arg("quality"))
      .def_property_readonly("num_anchors", &ForwardFilter::num_anchors)
      .def_property_readonly("num_conditions", &ForwardFilter::num_conditions)
      .def_property_readonly("step_index", &ForwardFilter::step_index)
      .def_property_readonly("process", &ForwardFilter::process, py::return_value_policy::copy,
                             "The sight chains (a copy).")
      .def_property_readonly("quality", &ForwardFilter::quality, py::return_value_policy::copy,
                             "The quality likelihoods (a copy).")
      .def_property_readonly("last_log_evidence", &ForwardFilter::last_log_evidence,
                             "log p(o_t | o_1:t-1) of the last update.")
      .def("reset", &ForwardFilter::reset)
      .def(
          "set_probabilities",
          [](ForwardFilter& f, const bind::MatArg& gamma) { f.set_probabilities(gamma.get("gamma")); },
          py::arg("gamma"),
          "Replaces the probabilities (B, N_z) (rows >= 0 summing to 1); also the prior of the next update.")
      .def(
          "predict", [](ForwardFilter& f, const bind::VecArg& speeds) { f.predict(speeds.get("speeds")); },
          py::arg("speeds") = VecX(), "Prediction, eq. (36).")
      .def("update", bind::vector_method<ForwardFilter, &ForwardFilter::update>("o"), py::arg("o"),
           "Update with o (B,) (NaN = missing), eqs. (37)-(38); returns log p(o_t | o_1:t-1).")
      .def(
          "step",
          [](ForwardFilter& f, const bind::VecArg& o, const bind::VecArg& speeds) {
            return f.step(o.get("o"), speeds.get("speeds"));
          },
          py::arg("o"), py::arg("speeds") = VecX(),
          "predict(speeds) then update(o); a rejected call changes nothing.")
      .def_property_readonly("probabilities", &ForwardFilter::probabilities, py::return_value_policy::copy,
                             "(B, N_z) P(s_b = z | o_b,1:t).")
      .def_property_readonly("predicted", &ForwardFilter::predicted, py::return_value_policy::copy)
      .def("argmax", &ForwardFilter::argmax)
      .def(
          "save",
          [](const ForwardFilter& f) {
            ForwardFilter::Snapshot snap;
            f.save(snap);
            return snap;
          },
          "Snapshot of the mutable state (probabilities, step, evidence), to undo steps with restore().")
      .def("restore", &ForwardFilter::restore, py::arg("snapshot"),
           "Restores a snapshot from save() (shapes are checked).");
}
}  // namespace nlosloc::bind_situation_cpp

void bind_situation(py::module_& m) { nlosloc::bind_situation_cpp::define_module(m); }
