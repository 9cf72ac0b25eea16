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
#include "nlosloc/snapshot/snapshot.hpp"

namespace py = pybind11;
using namespace nlosloc;
using namespace nlosloc::snapshot;

namespace {

VecX theta_out(const Theta& t) { return VecX(t); }

Theta theta_in(const VecX& v, int n, const char* name) {
  detail::ensure_shape(v, n, 1, name);
  return Theta(v);
}

std::vector<char> flags_in(const std::vector<bool>& use) { return std::vector<char>(use.begin(), use.end()); }

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
       "reset", [](S& s, const VecX& start) { s.reset(theta_in(start, s.solver().unknowns(), "start")); },
       py::arg("start"),
       "Sets the start of every fix: position (D) then clock bias (RTOA stacks); forgets warm starts.")
      .def(
          "solve", [](S& s, const VecX& y) { return result_dict(s.solve(y)); }, py::arg("y"),
          "Fix of one epoch y (rows of the stack, NaN = missing).\n\nReturns\n-------\ndict\n    theta "
          "(position "
          "then clock bias), valid, cost, sight (0 LOS / 1 NLOS per anchor, zeros when the method does not "
          "classify), fixes (Gauss-Newton solves).")
      .def_property_readonly("classifies_sight", &S::classifies_sight, "True when solve() decides the sight.")
      .def_property_readonly(
          "sight", [](const S& s) { return VecXi(s.sight()); }, "Sight decision of the last epoch (B).")
      .def_property_readonly(
          "unknowns", [](const S& s) { return s.solver().unknowns(); }, "D, plus 1 with RTOA rows.");
}

}  // namespace

void bind_snapshot(py::module_& m) {
  py::class_<RowNoise>(m, "RowNoise",
                       "Noise model of one row in a fix: Gaussian or split (asymmetric) normal.")
      .def(py::init([](double center, double sigma_left, double sigma_right) {
             detail::ensure_positive(sigma_left, "sigma_left");
             detail::ensure_positive(sigma_right, "sigma_right");
             return RowNoise{center, sigma_left, sigma_right};
           }),
           py::arg("center"), py::arg("sigma_left"), py::arg("sigma_right"))
      .def_static(
          "gaussian",
          [](double mean, double std) {
            detail::ensure_positive(std, "std");
            return RowNoise::gaussian(mean, std);
          },
          py::arg("mean"), py::arg("std"), "Gaussian N(mean, std^2).")
      .def_static("split", &RowNoise::split, py::arg("dist"),
                  "From a noise.AsymmetricNormal (Cong & Zhuang 2005).")
      .def_readwrite("center", &RowNoise::center)
      .def_readwrite("sigma_left", &RowNoise::sigma_left)
      .def_readwrite("sigma_right", &RowNoise::sigma_right)
      .def("log_pdf", &RowNoise::log_pdf, py::arg("r"), "log density of the residual r.")
      .def("__repr__", [](const RowNoise& r) {
        return "RowNoise(center=" + std::to_string(r.center) +
               ", sigma_left=" + std::to_string(r.sigma_left) +
               ", sigma_right=" + std::to_string(r.sigma_right) + ")";
      });

  py::class_<GaussNewtonOptions>(m, "GaussNewtonOptions",
                                 "Options of the Gauss-Newton / Levenberg-Marquardt fix.")
      .def(py::init<>())
      .def_readwrite("max_iterations", &GaussNewtonOptions::max_iterations)
      .def_readwrite("step_tolerance", &GaussNewtonOptions::step_tolerance)
      .def_readwrite("initial_damping", &GaussNewtonOptions::initial_damping)
      .def_readwrite("max_damping", &GaussNewtonOptions::max_damping);

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
           py::arg("options") = GaussNewtonOptions())
      .def_property_readonly("unknowns", &LosSolver::unknowns)
      .def_property_readonly("has_clock", &LosSolver::has_clock)
      .def_property_readonly("los_noise", &LosSolver::los_noise, "The LOS Gaussian RowNoise of every row.")
      .def(
          "solve",
          [](const LosSolver& s, const VecX& y, const VecX& theta0,
             const std::optional<std::vector<bool>>& use, const std::optional<std::vector<RowNoise>>& noise) {
            const auto m = static_cast<std::size_t>(s.stack().rows());
            const std::vector<char> u = use ? flags_in(*use) : std::vector<char>(m, 1);
            return s.solve(y, theta_in(theta0, s.unknowns(), "theta0"), u, noise ? *noise : s.los_noise());
          },
          py::arg("y"), py::arg("theta0"), py::arg("use") = py::none(), py::arg("noise") = py::none(),
          "Fix from the rows flagged in `use` (default all) with per-row RowNoise `noise` (default LOS).")
      .def(
          "linear_start",
          [](const LosSolver& s, const VecX& y, const std::optional<std::vector<bool>>& use) -> py::object {
            const auto m = static_cast<std::size_t>(s.stack().rows());
            Theta t;
            if (!s.linear_start(y, use ? flags_in(*use) : std::vector<char>(m, 1), t)) return py::none();
            return py::cast(theta_out(t));
          },
          py::arg("y"), py::arg("use") = py::none(),
          "Closed-form linear LS start of the TOA/RTOA rows, or None when too few rows.");

  py::class_<ChenOptions>(m, "ChenOptions", "Options of Chen.")
      .def(py::init<>())
      .def_readwrite("min_size", &ChenOptions::min_size)
      .def_readwrite("reject_fraction", &ChenOptions::reject_fraction)
      .def_readwrite("residual_floor", &ChenOptions::residual_floor);
  py::class_<CongOptions>(m, "CongOptions", "Options of Cong.")
      .def(py::init<>())
      .def_readwrite("confidence", &CongOptions::confidence)
      .def_readwrite("negative_sigmas", &CongOptions::negative_sigmas)
      .def_readwrite("min_los", &CongOptions::min_los)
      .def_readwrite("min_rows", &CongOptions::min_rows)
      .def_readwrite("fit_samples", &CongOptions::fit_samples)
      .def_readwrite("fit_seed", &CongOptions::fit_seed);
  py::class_<UrruelaOptions>(m, "UrruelaOptions", "Options of Urruela.")
      .def(py::init<>())
      .def_readwrite("p_nlos", &UrruelaOptions::p_nlos)
      .def_readwrite("p_ln", &UrruelaOptions::p_ln)
      .def_readwrite("p_nl", &UrruelaOptions::p_nl)
      .def_readwrite("nlos_span", &UrruelaOptions::nlos_span);

  {
    py::class_<MleLos> c(m, "MleLos",
                         "MLE-LOS (Huerta Sec. VI-A): per-epoch ML fix with every anchor assumed LOS.");
    c.def(py::init<const MeasurementStack&, const GaussNewtonOptions&>(), py::arg("measurements"),
          py::arg("options") = GaussNewtonOptions());
    baseline_methods<MleLos>(c);
  }
  {
    py::class_<Chen> c(m, "Chen",
                       "CHEN: Chen 1999 residual weighting over anchor combinations, 50% of the combinations "
                       "with the largest normalised residual rejected (Huerta Sec. VI-B).");
    c.def(py::init<const MeasurementStack&, const ChenOptions&, const GaussNewtonOptions&>(),
          py::arg("measurements"), py::arg("options") = ChenOptions(),
          py::arg("gauss_newton") = GaussNewtonOptions());
    baseline_methods<Chen>(c);
    c.def_property_readonly("combinations", &Chen::combinations, "Anchor bit masks of the combinations.");
  }
  {
    py::class_<Cong> c(
        m, "Cong",
        "CONG: Cong & Zhuang 2005 residual-test NLOS identification; with too few LOS anchors the "
        "smallest-residual rows under an asymmetric Gaussian fit of the NLOS noise.");
    c.def(py::init<const MeasurementStack&, const CongOptions&, const GaussNewtonOptions&>(),
          py::arg("measurements"), py::arg("options") = CongOptions(),
          py::arg("gauss_newton") = GaussNewtonOptions());
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
          py::arg("measurements"), py::arg("options") = UrruelaOptions(),
          py::arg("gauss_newton") = GaussNewtonOptions());
    baseline_methods<Urruela>(c);
    c.def_property_readonly("hypotheses", &Urruela::hypotheses, "LOS anchor bit masks of the trellis states.")
        .def_property_readonly("path_metrics", &Urruela::path_metrics, "Viterbi metrics (minimum 0).");
  }
}
