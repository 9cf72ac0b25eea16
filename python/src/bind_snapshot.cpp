/// \file bind_snapshot.cpp
/// nlosloc.snapshot: the per-epoch baselines of Huerta et al. 2009 Sec. VI (MleLos, Chen, Cong, Urruela),
/// their options, the Gauss-Newton LosSolver and its RowNoise / Fix types. Same names as in C++.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "bind.hpp"
#include "native_makers.hpp"
#include "nlosloc/snapshot/estimator.hpp"
#include "nlosloc/snapshot/snapshot.hpp"
#include "params_field.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_snapshot_cpp {
using namespace nlosloc::snapshot;

namespace {

VecX theta_out(const Theta& t) { return VecX(t); }

Theta theta_in(const VecX& v, int n, const char* name) {
  detail::ensure_shape(v, n, 1, name);
  detail::ensure_finite(v, name);  // a NaN start gave a "fix" of NaN with cost inf and no error
  return Theta(v);
}

std::vector<char> flags_in(const std::vector<bool>& use) { return std::vector<char>(use.begin(), use.end()); }

/// `use` from Python (None: every row) for a solver of `m` rows.
std::vector<char> flags_or_all(const std::optional<std::vector<bool>>& use, int m) {
  return use ? flags_in(*use) : std::vector<char>(static_cast<std::size_t>(m), 1);
}

/// A RowNoise setter that keeps the model valid (RowNoise::check names the field; field_value names it
/// for a value that is not a real number).
template <double RowNoise::*Field>
auto set_checked(const char* name) {
  return [name](RowNoise& r, const bind::StrictArg<double>& v) {
    RowNoise t = r;
    t.*Field = bind::field_value<double>(v.obj, std::string("RowNoise.") + name);
    t.check("RowNoise");
    r = t;
  };
}

py::dict result_dict(const SnapshotResult& r) {
  py::dict d;
  d["theta"] = theta_out(r.theta);
  d["valid"] = r.valid;
  d["cost"] = r.cost;
  d["sight"] = VecXi(r.sight);
  d["fixes"] = r.fixes;
  return d;
}

/// reset / solve / sight shared by the four baselines.
template <class S, class C>
void baseline_methods(C& c) {
  c.def(
       "reset",
       [](S& s, const bind::VecArg& start_in) {
         const VecX start = start_in.get("start");
         s.reset(theta_in(start, s.solver().unknowns(), "start"));
       },
       py::arg("start"),
       "Sets the start of every fix: position (D) then clock bias (RTOA stacks); forgets warm starts.")
      .def(
          "solve",
          [](S& s, const bind::VecArg& y_in) {
            const VecX y = y_in.get("y");
            return result_dict(s.solve(y));
          },
          py::arg("y"),
          "Fix of one epoch y (rows of the stack, NaN = missing).\n\nReturns\n-------\ndict\n    theta "
          "(position "
          "then clock bias), valid, cost, sight (0 LOS / 1 NLOS per anchor, zeros when the method does not "
          "classify), fixes (Gauss-Newton solves).")
      .def_property_readonly("classifies_sight", &S::classifies_sight, "True when solve() decides the sight.")
      .def_property_readonly(
          "sight", [](const S& s) { return VecXi(s.sight()); }, "Sight decision of the last epoch (B).")
      .def_property_readonly(
          "unknowns", [](const S& s) { return s.solver().unknowns(); }, "D, plus 1 with RTOA rows.")
      .def_property_readonly(
          "options", [](const S& s) { return s.options(); }, "A copy of the options it was built with.")
      .def_property_readonly(
          "gauss_newton", [](const S& s) { return s.solver().options(); },
          "A copy of the GaussNewtonOptions of its solver.")
      .def_property_readonly(
          "solver", [](const S& s) { return s.solver(); },
          "A copy of its LosSolver (the per-epoch Gauss-Newton fix on its measurement stack).");
}

}  // namespace

void define_module(py::module_& m) {
  py::class_<RowNoise>(m, "RowNoise",
                       "Noise model of one row in a fix: Gaussian or split (asymmetric) normal.")
      .def(py::init([](const bind::StrictArg<double>& center, const bind::StrictArg<double>& sigma_left,
                       const bind::StrictArg<double>& sigma_right) {
             const RowNoise r{center.get("center"), sigma_left.get("sigma_left"),
                              sigma_right.get("sigma_right")};
             r.check("RowNoise");
             return r;
           }),
           py::arg("center"), py::arg("sigma_left"), py::arg("sigma_right"),
           "center finite; sigma_left, sigma_right finite > 0 (ValueError naming the field otherwise).")
      .def_static("gaussian", &RowNoise::gaussian, py::arg("mean"), py::arg("std"),
                  "Gaussian N(mean, std^2): mean finite, std finite > 0.")
      .def_static("split", &RowNoise::split, py::arg("dist"),
                  "From a noise.AsymmetricNormal (Cong & Zhuang 2005).")
      .def_property(
          "center", [](const RowNoise& r) { return r.center; }, set_checked<&RowNoise::center>("center"),
          "Mean (Gaussian) or mode (split normal) of the noise; finite.")
      .def_property(
          "sigma_left", [](const RowNoise& r) { return r.sigma_left; },
          set_checked<&RowNoise::sigma_left>("sigma_left"),
          "Standard deviation left of the center; finite > 0.")
      .def_property(
          "sigma_right", [](const RowNoise& r) { return r.sigma_right; },
          set_checked<&RowNoise::sigma_right>("sigma_right"),
          "Standard deviation right of the center; finite > 0.")
      .def("valid", &RowNoise::valid, "True when center is finite and both sigmas are finite > 0.")
      .def("log_pdf", &RowNoise::log_pdf, py::arg("r"), "log density of the residual r.")
      .def("normalized", &RowNoise::normalized, py::arg("r"),
           "Normalised residual (r - center) / sigma, with sigma_left below the center, sigma_right above.");

  py::class_<GaussNewtonOptions>(m, "GaussNewtonOptions",
                                 "Options of the Gauss-Newton / Levenberg-Marquardt fix.")
      .def(py::init<>())
      .def_property("max_iterations", bind::field_get<&GaussNewtonOptions::max_iterations>(),
                    bind::field_set<&GaussNewtonOptions::max_iterations>("max_iterations"))
      .def_property("step_tolerance", bind::field_get<&GaussNewtonOptions::step_tolerance>(),
                    bind::field_set<&GaussNewtonOptions::step_tolerance>("step_tolerance"))
      .def_property("initial_damping", bind::field_get<&GaussNewtonOptions::initial_damping>(),
                    bind::field_set<&GaussNewtonOptions::initial_damping>("initial_damping"))
      .def_property("max_damping", bind::field_get<&GaussNewtonOptions::max_damping>(),
                    bind::field_set<&GaussNewtonOptions::max_damping>("max_damping"));

  py::class_<Fix>(m, "Fix", "Result of one Gauss-Newton fix.")
      .def_property_readonly(
          "theta", [](const Fix& f) { return theta_out(f.theta); }, "Position (D) then clock bias.")
      .def_readonly("cost", &Fix::cost, "Sum of squared normalised residuals.")
      .def_readonly("rows", &Fix::rows)
      .def_readonly("iterations", &Fix::iterations)
      .def_readonly("converged", &Fix::converged);

  py::class_<LosSolver>(
      m, "LosSolver",
      "Per-epoch damped Gauss-Newton fix of position (and clock bias for RTOA rows) on a "
      "MeasurementStack (the MLE-LOS of Huerta Sec. VI-A and the inner solver of the baselines).")
      .def(py::init<const MeasurementStack&, const GaussNewtonOptions&>(), py::arg("measurements"),
           py::arg_v("options", GaussNewtonOptions(), "GaussNewtonOptions()"))
      .def_property_readonly("unknowns", &LosSolver::unknowns, "D, plus 1 with RTOA rows.")
      .def_property_readonly("has_clock", &LosSolver::has_clock, "True when the clock bias is an unknown.")
      .def_property_readonly("space_dim", &LosSolver::space_dim, "Space dimension D.")
      .def_property_readonly(
          "options", [](const LosSolver& s) { return s.options(); },
          "A copy of the GaussNewtonOptions it was built with.")
      .def_property_readonly("los_noise", &LosSolver::los_noise, "The LOS Gaussian RowNoise of every row.")
      .def_property_readonly(
          "measurements", [](const LosSolver& s) { return s.stack(); }, "The measurement stack (a copy).")
      .def(
          "to_state",
          [](const LosSolver& s, const bind::VecArg& theta_arg) {
            const VecX theta = theta_arg.get("theta");
            VecX x;
            s.to_state(theta_in(theta, s.unknowns(), "theta"), x);
            return x;
          },
          py::arg("theta"),
          "The full state vector of the stack's layout (zeros but position and clock bias) of a fix theta.")
      .def(
          "residuals",
          [](const LosSolver& s, const bind::VecArg& y_in, const bind::VecArg& theta_arg) {
            const VecX y = y_in.get("y");
            const VecX theta = theta_arg.get("theta");
            VecX r;
            s.residuals(y, theta_in(theta, s.unknowns(), "theta"), r);
            return r;
          },
          py::arg("y"), py::arg("theta"),
          "Residuals y - g(theta) of every row (angle rows wrapped); y (rows,), theta (unknowns,).")
      .def(
          "cost",
          [](const LosSolver& s, const bind::VecArg& y_in, const bind::VecArg& theta_arg,
             const std::optional<std::vector<bool>>& use, const std::optional<std::vector<RowNoise>>& noise) {
            const VecX y = y_in.get("y");
            const VecX theta = theta_arg.get("theta");
            return s.cost(y, theta_in(theta, s.unknowns(), "theta"), flags_or_all(use, s.stack().rows()),
                          noise ? *noise : s.los_noise());
          },
          py::arg("y"), py::arg("theta"), py::arg("use") = py::none(), py::arg("noise") = py::none(),
          "Sum of squared normalised residuals ((r_i - c_i) / s_i)^2 over the rows flagged in `use` (default "
          "all; NaN rows skipped) with per-row RowNoise `noise` (default LOS).")
      .def(
          "rows_of",
          [](const LosSolver& s, AnchorMask mask) {
            std::vector<char> use;
            s.rows_of(mask, use);
            return std::vector<bool>(use.begin(), use.end());
          },
          py::arg("mask"), "Row flags of the rows whose anchor (both for TDOA) is in the bit mask `mask`.")
      .def(
          "solve",
          [](const LosSolver& s, const bind::VecArg& y_in, const bind::VecArg& theta0_in,
             const std::optional<std::vector<bool>>& use, const std::optional<std::vector<RowNoise>>& noise) {
            const VecX y = y_in.get("y");
            const VecX theta0 = theta0_in.get("theta0");
            return s.solve(y, theta_in(theta0, s.unknowns(), "theta0"), flags_or_all(use, s.stack().rows()),
                           noise ? *noise : s.los_noise());
          },
          py::arg("y"), py::arg("theta0"), py::arg("use") = py::none(), py::arg("noise") = py::none(),
          "Fix from the rows flagged in `use` (default all) with per-row RowNoise `noise` (default LOS).")
      .def(
          "solve_los",
          [](const LosSolver& s, const bind::VecArg& y_in, const bind::VecArg& theta0_in) {
            const VecX y = y_in.get("y");
            const VecX theta0 = theta0_in.get("theta0");
            return s.solve_los(y, theta_in(theta0, s.unknowns(), "theta0"));
          },
          py::arg("y"), py::arg("theta0"),
          "Fix from every row with the LOS Gaussian noise (MLE-LOS): solve(y, theta0) with the defaults.")
      .def(
          "linear_start",
          [](const LosSolver& s, const bind::VecArg& y_in,
             const std::optional<std::vector<bool>>& use) -> py::object {
            const VecX y = y_in.get("y");
            Theta t;
            if (!s.linear_start(y, flags_or_all(use, s.stack().rows()), t)) return py::none();
            return py::cast(theta_out(t));
          },
          py::arg("y"), py::arg("use") = py::none(),
          "Closed-form linear LS start of the TOA/RTOA rows, or None when too few rows.");

  m.def("mask_count", &mask_count, py::arg("mask"), "Number of anchors in an anchor bit mask.");
  m.def("subsets_at_least", &subsets_at_least, py::arg("num_anchors"), py::arg("min_size"),
        "Every anchor bit mask over num_anchors (1..20) anchors with at least min_size anchors, larger sets "
        "first, then ascending mask value.");

  py::class_<ChenOptions>(m, "ChenOptions", "Options of Chen.")
      .def(py::init<>())
      .def_property("min_size", bind::field_get<&ChenOptions::min_size>(),
                    bind::field_set<&ChenOptions::min_size>("min_size"))
      .def_property("reject_fraction", bind::field_get<&ChenOptions::reject_fraction>(),
                    bind::field_set<&ChenOptions::reject_fraction>("reject_fraction"))
      .def_property("residual_floor", bind::field_get<&ChenOptions::residual_floor>(),
                    bind::field_set<&ChenOptions::residual_floor>("residual_floor"));
  py::class_<CongOptions>(m, "CongOptions", "Options of Cong.")
      .def(py::init<>())
      .def_property("confidence", bind::field_get<&CongOptions::confidence>(),
                    bind::field_set<&CongOptions::confidence>("confidence"))
      .def_property("negative_sigmas", bind::field_get<&CongOptions::negative_sigmas>(),
                    bind::field_set<&CongOptions::negative_sigmas>("negative_sigmas"))
      .def_property("min_los", bind::field_get<&CongOptions::min_los>(),
                    bind::field_set<&CongOptions::min_los>("min_los"))
      .def_property("min_rows", bind::field_get<&CongOptions::min_rows>(),
                    bind::field_set<&CongOptions::min_rows>("min_rows"))
      .def_property("fit_samples", bind::field_get<&CongOptions::fit_samples>(),
                    bind::field_set<&CongOptions::fit_samples>("fit_samples"))
      .def_property("fit_seed", bind::field_get<&CongOptions::fit_seed>(),
                    bind::field_set<&CongOptions::fit_seed>("fit_seed"));
  py::class_<UrruelaOptions>(m, "UrruelaOptions", "Options of Urruela.")
      .def(py::init<>())
      .def_property("p_nlos", bind::field_get<&UrruelaOptions::p_nlos>(),
                    bind::field_set<&UrruelaOptions::p_nlos>("p_nlos"))
      .def_property("p_ln", bind::field_get<&UrruelaOptions::p_ln>(),
                    bind::field_set<&UrruelaOptions::p_ln>("p_ln"))
      .def_property("p_nl", bind::field_get<&UrruelaOptions::p_nl>(),
                    bind::field_set<&UrruelaOptions::p_nl>("p_nl"))
      .def_property("nlos_span", bind::field_get<&UrruelaOptions::nlos_span>(),
                    bind::field_set<&UrruelaOptions::nlos_span>("nlos_span"));

  {
    py::class_<MleLos> c(m, "MleLos",
                         "MLE-LOS (Huerta Sec. VI-A): per-epoch ML fix with every anchor assumed LOS.");
    c.def(py::init<const MeasurementStack&, const GaussNewtonOptions&>(), py::arg("measurements"),
          py::arg_v("options", GaussNewtonOptions(), "GaussNewtonOptions()"));
    baseline_methods<MleLos>(c);
  }
  {
    py::class_<Chen> c(m, "Chen",
                       "CHEN: Chen 1999 residual weighting over anchor combinations, 50% of the combinations "
                       "with the largest normalised residual rejected (Huerta Sec. VI-B).");
    c.def(py::init<const MeasurementStack&, const ChenOptions&, const GaussNewtonOptions&>(),
          py::arg("measurements"), py::arg_v("options", ChenOptions(), "ChenOptions()"),
          py::arg_v("gauss_newton", GaussNewtonOptions(), "GaussNewtonOptions()"));
    baseline_methods<Chen>(c);
    c.def_property_readonly("combinations", &Chen::combinations, "Anchor bit masks of the combinations.");
  }
  {
    py::class_<Cong> c(
        m, "Cong",
        "CONG: Cong & Zhuang 2005 residual-test NLOS identification; with too few LOS anchors the "
        "smallest-residual rows under an asymmetric Gaussian fit of the NLOS noise.");
    c.def(py::init<const MeasurementStack&, const CongOptions&, const GaussNewtonOptions&>(),
          py::arg("measurements"), py::arg_v("options", CongOptions(), "CongOptions()"),
          py::arg_v("gauss_newton", GaussNewtonOptions(), "GaussNewtonOptions()"));
    baseline_methods<Cong>(c);
    c.def_property_readonly("nlos_noise", &Cong::nlos_noise, "Fitted split normal of each row's NLOS noise.")
        .def_property_readonly("enough_los", &Cong::enough_los, "True when the last epoch found a LOS set.");
  }
  {
    py::class_<Urruela> c(
        m, "Urruela",
        "URR: Riba & Urruela ML detection of the LOS set with the Urruela-Morata-Riba trellis "
        "(Viterbi) search over time, on TDOA.");
    c.def(py::init<const MeasurementStack&, const UrruelaOptions&, const GaussNewtonOptions&>(),
          py::arg("measurements"), py::arg_v("options", UrruelaOptions(), "UrruelaOptions()"),
          py::arg_v("gauss_newton", GaussNewtonOptions(), "GaussNewtonOptions()"));
    baseline_methods<Urruela>(c);
    c.def_property_readonly("hypotheses", &Urruela::hypotheses, "LOS anchor bit masks of the trellis states.")
        .def_property_readonly("path_metrics", &Urruela::path_metrics, "Viterbi metrics (minimum 0).");
  }
}
}  // namespace nlosloc::bind_snapshot_cpp

void bind_snapshot(py::module_& m) { nlosloc::bind_snapshot_cpp::define_module(m); }

namespace nlosloc::bind {

/// A snapshot baseline of nlosloc.snapshot (MleLos, Chen, Cong, Urruela) as a sim::SnapshotEstimator over
/// a copy. Null when `h` is none of them.
template <class Solver>
NativeMaker snapshot_maker_of(const py::handle& h, const std::string& name, const char* what,
                              const sim::Scenario& s) {
  if (!py::isinstance<Solver>(h)) return nullptr;
  auto proto = std::make_shared<const Solver>(h.cast<const Solver&>());
  const MeasurementStack& st = proto->solver().stack();
  check_fit(name, what, st.layout().dim, st.rows(), st.num_anchors(), std::nan(""), s);
  if (st.layout().space_dim != s.space_dim())
    throw py::value_error(who(name, what) + "solves for " + std::to_string(st.layout().space_dim) +
                          "-D positions; scenario " + s.name() + " is " + std::to_string(s.space_dim()) +
                          "-D");
  return [name, proto] { return sim::make_snapshot_estimator(name, *proto); };
}

NativeMaker snapshot_maker(const py::handle& h, const std::string& name, const sim::Scenario& s) {
  if (NativeMaker m = snapshot_maker_of<snapshot::MleLos>(h, name, "MleLos", s)) return m;
  if (NativeMaker m = snapshot_maker_of<snapshot::Chen>(h, name, "Chen", s)) return m;
  if (NativeMaker m = snapshot_maker_of<snapshot::Cong>(h, name, "Cong", s)) return m;
  return snapshot_maker_of<snapshot::Urruela>(h, name, "Urruela", s);
}

}  // namespace nlosloc::bind
