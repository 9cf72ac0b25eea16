/// \file bind_bounds.cpp
/// nlosloc.bounds: GCRB of Huerta et al. 2009, Appendix (eqs. 41-48).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "bind.hpp"
#include "field_value.hpp"
#include "nlosloc/bounds/gcrb.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_bounds_cpp {

void define_module(py::module_& m) {
  py::class_<bounds::GcrbResult>(m, "GcrbResult", "Information matrices and position bounds of gcrb_rtoa.")
      .def_readonly("J", &bounds::GcrbResult::J, "(D+1, D+1) J = J_D + J_P, eq. (46).")
      .def_readonly("J_data", &bounds::GcrbResult::J_data, "J_D = H Q^-1 H^T, eq. (43).")
      .def_readonly("position_gcrb", &bounds::GcrbResult::position_gcrb, "(D, D) [J^-1]_p, eqs. (47)-(48).")
      .def_readonly("position_crb", &bounds::GcrbResult::position_crb, "(D, D) [J_D^-1]_p, no prior.");
  m.def("gcrb_rtoa", bind::strict_fn(&bounds::gcrb_rtoa, "anchors", "position", "Q", "sigma_tau2"),
        py::arg("anchors"), py::arg("position"), py::arg("Q"), py::arg("sigma_tau2"),
        "GCRB of the position from RTOA with a clock prior of variance sigma_tau2 (inf: no prior). anchors "
        "(B, D), position (D,), Q (B, B) measurement covariance: positive definite and symmetric "
        "(max |Q - Q^T| <= 1e-10 ||Q||_F; ValueError naming Q otherwise).");
}
}  // namespace nlosloc::bind_bounds_cpp

void bind_bounds(py::module_& m) { nlosloc::bind_bounds_cpp::define_module(m); }
