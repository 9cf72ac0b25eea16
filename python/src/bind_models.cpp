/// \file bind_models.cpp
/// nlosloc.models: motion models and the measurement stack.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bind.hpp"
#include "field_value.hpp"
#include "int_arg.hpp"
#include "motion_arg.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/models/motion.hpp"
#include "params_field.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_models_cpp {

namespace {
template <class M, class Cls>
void motion_common(Cls& c) {
  c.def_property_readonly("dt", &M::dt, "Time step (s).")
      .def_property_readonly("F", &M::F, "Transition matrix, shape (n, n).")
      .def_property_readonly("Q", &M::Q, "Process-noise covariance, shape (n, n).")
      .def_property_readonly_static(
          "dim", [](py::object) { return M::kDim; }, "State size n.")
      .def_static("layout", &M::layout, "Where position, velocity and clock sit in the state.");
}
template <int D>
void bind_cv(py::module_& m, const char* name) {
  using M = ConstantVelocity<D>;
  py::class_<M> c(m, name,
                  (std::string("Constant velocity in ") + std::to_string(D) +
                   "-D, state [p, v] (Huerta eqs. 6-7 random walk, Ke and Wu eq. 16 white acceleration).")
                      .c_str());
  c.def(bind::strict_init<M, double, double, VelocityNoise>("dt", "sigma2", "noise"), py::arg("dt"),
        py::arg("sigma2"), py::arg("noise") = VelocityNoise::kRandomWalk,
        "dt > 0 (s); sigma2 >= 0: velocity random-walk rate ((m/s)^2/s) or acceleration variance "
        "((m/s^2)^2) depending on `noise`.")
      .def_property_readonly("sigma2", &M::sigma2)
      .def_property_readonly("noise", &M::noise);
  motion_common<M>(c);
}
template <int D>
void bind_cvc(py::module_& m, const char* name) {
  using M = ConstantVelocityClock<D>;
  py::class_<M> c(m, name,
                  "Constant velocity plus clock bias (light-metres) and drift, state [p, tau, v, tau_dot] "
                  "(Huerta eqs. 5-7).");
  c.def(bind::strict_init<M, double, double, double>("dt", "sigma_v2", "sigma_tau2"), py::arg("dt"),
        py::arg("sigma_v2"), py::arg("sigma_tau2"),
        "dt > 0 (s); sigma_v2 >= 0 ((m/s)^2/s); sigma_tau2 >= 0 ((lm/s)^2/s).")
      .def_property_readonly("sigma_v2", &M::sigma_v2)
      .def_property_readonly("sigma_tau2", &M::sigma_tau2);
  motion_common<M>(c);
}
}  // namespace

void define_module(py::module_& m) {
  py::class_<StateLayout>(m, "StateLayout", "Indices of the state pieces (-1 = absent).")
      .def(py::init<>())
      .def_property("dim", bind::field_get<&StateLayout::dim>(), bind::field_set<&StateLayout::dim>("dim"))
      .def_property("space_dim", bind::field_get<&StateLayout::space_dim>(),
                    bind::field_set<&StateLayout::space_dim>("space_dim"))
      .def_property("position", bind::field_get<&StateLayout::position>(),
                    bind::field_set<&StateLayout::position>("position"))
      .def_property("velocity", bind::field_get<&StateLayout::velocity>(),
                    bind::field_set<&StateLayout::velocity>("velocity"))
      .def_property("clock_bias", bind::field_get<&StateLayout::clock_bias>(),
                    bind::field_set<&StateLayout::clock_bias>("clock_bias"))
      .def_property("clock_drift", bind::field_get<&StateLayout::clock_drift>(),
                    bind::field_set<&StateLayout::clock_drift>("clock_drift"))
      .def_property("skew", bind::field_get<&StateLayout::skew>(),
                    bind::field_set<&StateLayout::skew>("skew"))
      .def_property("offset", bind::field_get<&StateLayout::offset>(),
                    bind::field_set<&StateLayout::offset>("offset"));

  py::enum_<VelocityNoise>(m, "VelocityNoise", "Process-noise form of the constant-velocity model.")
      .value("RandomWalk", VelocityNoise::kRandomWalk, "Huerta eqs. (6)-(7)")
      .value("WhiteAcceleration", VelocityNoise::kWhiteAcceleration, "Ke and Wu eq. (16)");

  bind_cv<2>(m, "ConstantVelocity2");
  bind_cv<3>(m, "ConstantVelocity3");
  bind_cvc<2>(m, "ConstantVelocityClock2");
  bind_cvc<3>(m, "ConstantVelocityClock3");
  py::class_<TwoWayClock> tw(m, "TwoWayClock",
                             "Two-way-ranging clock and mobility model, state (omega, phi, vx, vy, x, y) "
                             "(Grisales and Fierens eqs. 14-15).");
  tw.def(bind::strict_init<TwoWayClock, double, double, double, double>("h", "sigma_omega", "sigma_phi",
                                                                        "sigma_v"),
         py::arg("h"), py::arg("sigma_omega"), py::arg("sigma_phi"), py::arg("sigma_v"),
         "h > 0: period (s); step standard deviations of skew, offset (s), velocity (m/s).")
      .def_property_readonly("sigma_omega", &TwoWayClock::sigma_omega)
      .def_property_readonly("sigma_phi", &TwoWayClock::sigma_phi)
      .def_property_readonly("sigma_v", &TwoWayClock::sigma_v);
  motion_common<TwoWayClock>(tw);

  py::enum_<RowKind>(m, "RowKind", "Kind of a measurement row.")
      .value("Toa", RowKind::kToa)
      .value("Rtoa", RowKind::kRtoa)
      .value("Tdoa", RowKind::kTdoa)
      .value("Aoa", RowKind::kAoa)
      .value("AoaPhase", RowKind::kAoaPhase)
      .value("TwrTau", RowKind::kTwrTau)
      .value("TwrT", RowKind::kTwrT)
      .value("Linear", RowKind::kLinear);

  py::class_<MeasurementRow>(m, "MeasurementRow", "Description of one row of a MeasurementStack.")
      .def_readonly("kind", &MeasurementRow::kind)
      .def_readonly("anchor", &MeasurementRow::anchor)
      .def_readonly("anchor2", &MeasurementRow::anchor2)
      .def_readonly("input", &MeasurementRow::input)
      .def_readonly("inputs", &MeasurementRow::inputs)
      .def_readonly("sector_center", &MeasurementRow::sector_center)
      .def_readonly("slot", &MeasurementRow::slot)
      .def_readonly("linear", &MeasurementRow::linear,
                    "Linear rows: index of the row's coefficients among the stack's linear rows; else -1.");

  py::class_<MeasurementStack::TwrParams>(m, "TwrParams", "Parameters of a two-way-ranging pair (add_twr).")
      .def_readonly("delta_slot", &MeasurementStack::TwrParams::delta_slot, "Delta (s).")
      .def_readonly("reply_delay", &MeasurementStack::TwrParams::reply_delay, "delta (s).")
      .def_readonly("sigma_m", &MeasurementStack::TwrParams::sigma_m, "Time-stamping noise std (s).")
      .def_readonly("gamma", &MeasurementStack::TwrParams::gamma,
                    "NLOS delay distribution per condition (None: no delay).");

  py::class_<MeasurementStack>(
      m, "MeasurementStack",
      "Stack of measurement rows y = g(x) + n(s), each tied to an anchor whose sight condition s selects the "
      "row's noise (Huerta Table I; Grisales eqs. 17-20). Build it once with the add_* methods.")
      .def(py::init([](const StateLayout& layout, const bind::MatArg& anchors,
                       const bind::StrictArg<int>& num_conditions) {
             return MeasurementStack(layout, anchors.get("anchors"), num_conditions.get("num_conditions"));
           }),
           py::arg("layout"), py::arg("anchors"), py::arg("num_conditions") = 2,
           "layout: from the motion model (e.g. ConstantVelocity2.layout()); anchors: (B, D) positions in m; "
           "num_conditions: sight conditions per anchor (0 = LOS).")
      .def("add_toa", bind::strict_method(&MeasurementStack::add_toa, "anchor", "noise"), py::arg("anchor"),
           py::arg("noise"), py::return_value_policy::reference_internal,
           "TOA row; `noise`: one distribution per condition.")
      .def("add_rtoa", bind::strict_method(&MeasurementStack::add_rtoa, "anchor", "noise"), py::arg("anchor"),
           py::arg("noise"), py::return_value_policy::reference_internal,
           "RTOA (pseudorange) row, needs a clock-bias state.")
      .def("add_aoa", bind::strict_method(&MeasurementStack::add_aoa, "anchor", "noise"), py::arg("anchor"),
           py::arg("noise"), py::return_value_policy::reference_internal,
           "Geometric AOA row (rad), residuals wrapped.")
      .def("add_aoa_phase",
           bind::strict_method(&MeasurementStack::add_aoa_phase, "anchor", "sector_center", "noise"),
           py::arg("anchor"), py::arg("sector_center"), py::arg("noise"),
           py::return_value_policy::reference_internal,
           "ULA phase row psi = pi sin(theta - sector_center) (scenario H1).")
      .def("add_tdoa",
           bind::strict_method(&MeasurementStack::add_tdoa, "anchor_a", "anchor_b", "noise_a", "noise_b"),
           py::arg("anchor_a"), py::arg("anchor_b"), py::arg("noise_a"), py::arg("noise_b"),
           py::return_value_policy::reference_internal,
           "TDOA row ||p - q_a|| - ||p - q_b|| with noise n_a - n_b.")
      .def("add_twr",
           bind::strict_method(&MeasurementStack::add_twr, "anchor", "slot", "delta_slot", "reply_delay",
                               "sigma_m", "gamma"),
           py::arg("anchor"), py::arg("slot"), py::arg("delta_slot"), py::arg("reply_delay"),
           py::arg("sigma_m"), py::arg("gamma"), py::return_value_policy::reference_internal,
           "Two-way-ranging pair (tau, T) of Grisales eqs. (17)-(20); gamma[z]: NLOS delay distribution of "
           "condition z, None for no delay.")
      .def("add_linear", bind::strict_method(&MeasurementStack::add_linear, "h", "anchor", "noise"),
           py::arg("h"), py::arg("anchor"), py::arg("noise"), py::return_value_policy::reference_internal,
           "Linear row h^T x.")
      .def_property_readonly("rows", &MeasurementStack::rows)
      .def_property_readonly("noise_dim", &MeasurementStack::noise_dim)
      .def_property_readonly("num_anchors", &MeasurementStack::num_anchors)
      .def_property_readonly("num_conditions", &MeasurementStack::num_conditions)
      .def_property_readonly("layout", &MeasurementStack::layout, py::return_value_policy::copy)
      .def_property_readonly("anchors", &MeasurementStack::anchors)
      .def("row", &MeasurementStack::row, py::arg("i"))
      .def("noise", &MeasurementStack::noise, py::arg("i"), py::arg("condition"),
           "Noise distribution of row i under a condition (the first anchor's for TDOA); ValueError for a "
           "two-way-ranging row (see twr_params).")
      .def("noise_b", &MeasurementStack::noise_b, py::arg("i"), py::arg("condition"),
           "Noise of the second anchor (n_b of n_a - n_b) of TDOA row i.")
      .def("twr_params", &MeasurementStack::twr_params, py::arg("i"), py::return_value_policy::copy,
           "Parameters of two-way-ranging row i (either row of its pair), as given to add_twr.")
      .def(
          "linear_h",
          [](const MeasurementStack& s, bind::IndexArg i) { return VecX(s.linear_h(i.get("i"))); },
          py::arg("i"), "h of linear row i (y = h^T x + n), a copy.")
      .def(
          "predict",
          [](const MeasurementStack& s, const bind::VecArg& x_in, const bind::StrictArg<double>& t_in) {
            const VecX x = x_in.get("x");
            const double t = t_in.get("t");
            detail::ensure_shape(x, s.layout().dim, 1, "x");
            VecX y(s.rows());
            s.predict(x, t, y);
            return y;
          },
          py::arg("x"), py::arg("t") = 0.0, "Noise-free prediction g(x), shape (rows,).")
      .def(
          "predict_columns",
          [](const MeasurementStack& s, const bind::MatArg& X_in, const bind::StrictArg<double>& t_in) {
            const MatX X = X_in.get("X");
            const double t = t_in.get("t");
            detail::ensure_shape(X, s.layout().dim, -1, "X");
            MatX Z(s.rows(), X.cols());
            s.predict_columns(X, t, Z);
            return Z;
          },
          py::arg("X"), py::arg("t") = 0.0,
          "g at every column of X (n, K): shape (rows, K), as predict() per column (the UKF's sigma-point "
          "path, row by row).")
      .def(
          "jacobian",
          [](const MeasurementStack& s, const bind::VecArg& x_in, const bind::StrictArg<double>& t_in) {
            const VecX x = x_in.get("x");
            const double t = t_in.get("t");
            detail::ensure_shape(x, s.layout().dim, 1, "x");
            MatX J(s.rows(), x.size());
            s.jacobian(x, t, J);
            return J;
          },
          py::arg("x"), py::arg("t") = 0.0, "Analytic Jacobian dg/dx, shape (rows, n).")
      .def(
          "noise_moments",
          [](const MeasurementStack& s, const bind::VecArg& x_in, const py::object& sight_obj) {
            const VecX x = x_in.get("x");
            detail::ensure_shape(x, s.layout().dim, 1, "x");
            const VecXi sight = bind::to_sight(sight_obj);
            s.check_sight(sight);
            VecX mean(s.rows());
            MatX cov(s.rows(), s.rows());
            s.noise_moments(x, sight, mean, cov);
            return py::make_tuple(mean, cov);
          },
          py::arg("x"), py::arg("sight"), "(mean, cov) of the noise under `sight` at x.")
      .def(
          "predict_augmented",
          [](const MeasurementStack& s, const bind::VecArg& x_in, const bind::StrictArg<double>& t_in,
             const bind::VecArg& u_in, const py::object& sight_obj) {
            const VecX x = x_in.get("x");
            const VecX u = u_in.get("u");
            const double t = t_in.get("t");
            detail::ensure_shape(x, s.layout().dim, 1, "x");
            detail::ensure_shape(u, s.noise_dim(), 1, "u");
            const VecXi sight = bind::to_sight(sight_obj);
            s.check_sight(sight);
            VecX y(s.rows());
            s.predict_augmented(x, t, u, sight, y);
            return y;
          },
          py::arg("x"), py::arg("t"), py::arg("u"), py::arg("sight"),
          "g(x) plus noise built from standard normals u (noise_dim,) through each quantile map.")
      .def(
          "residual",
          [](const MeasurementStack& s, const bind::VecArg& a_in, const bind::VecArg& b_in) {
            const VecX a = a_in.get("a");
            const VecX b = b_in.get("b");
            detail::ensure_shape(a, s.rows(), 1, "a");
            detail::ensure_shape(b, s.rows(), 1, "b");
            VecX r = a - b;
            s.wrap_residual(r);
            return r;
          },
          py::arg("a"), py::arg("b"), "a - b with angle rows wrapped to (-pi, pi].")
      .def("is_angle", &MeasurementStack::is_angle, py::arg("i"))
      .def_property_readonly("has_angles", &MeasurementStack::has_angles,
                             "True when any row is an angle (AOA).")
      .def(
          "check_sight",
          [](const MeasurementStack& st, const py::object& sight) {
            st.check_sight(bind::to_sight(sight), "sight");
          },
          py::arg("sight"),
          "Raises ValueError unless sight is (B,) integers in [0, num_conditions): the check every filter "
          "applies to a sight vector.");
}
}  // namespace nlosloc::bind_models_cpp

void bind_models(py::module_& m) { nlosloc::bind_models_cpp::define_module(m); }
