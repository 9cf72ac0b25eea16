/// \file bind_filters.cpp
/// nlosloc.filters: KF, EKF, UKF and augmented UKF. The C++ filters are templates over the motion model;
/// Python sees one class per filter holding a std::variant over the motion models (AnyFilter,
/// any_filter.hpp).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <variant>

#include "any_filter.hpp"
#include "batch.hpp"
#include "bind.hpp"
#include "motion_arg.hpp"
#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/filters/kf.hpp"
#include "nlosloc/filters/ukf.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_filters_cpp {

namespace {
using bind::AnyFilter;
using bind::EkfT;
using bind::KfT;
using bind::to_gaussian;
using bind::to_motion;
using bind::UkfAugT;
using bind::UkfT;

/// Reads the optional sight argument of step/update: None, or (B,) integers.
std::optional<VecXi> sight_arg(const py::object& s) {
  if (s.is_none()) return std::nullopt;
  return bind::to_sight(s);
}

/// Runs T steps over Y (T, m) in one call with the GIL released. `sight`: None, (B,) for every step, or
/// (T, B). Every row is checked before the first step (batch.hpp). Returns mean (T, n), cov (T, n, n),
/// log_likelihood (T,), rows_used (T,).
template <class Filter>
py::dict run_batch(
    Filter& f,
    const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>& Y,
    const py::object& sight_obj, int m, int B) {
  constexpr int N = Filter::kDim;
  detail::ensure_shape(Y, -1, m, "Y");
  const Eigen::Index T = Y.rows();
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> S;
  bool per_step = false;
  const bool have_sight = !sight_obj.is_none();
  if (have_sight) {
    int ndim = 0;
    S = bind::to_int_rows(sight_obj, "sight", &ndim);
    per_step = ndim == 2;
    if (!((ndim == 1 && S.cols() == B) || (per_step && S.rows() == T && S.cols() == B)))
      throw std::invalid_argument("sight: expected shape (B,) or (T, B) with B = " + std::to_string(B) +
                                  ", T = " + std::to_string(T));
  }
  py::array_t<double> means({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(N)});
  py::array_t<double> covs(
      {static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(N), static_cast<py::ssize_t>(N)});
  py::array_t<double> ll(static_cast<py::ssize_t>(T));
  py::array_t<int> used(static_cast<py::ssize_t>(T));
  double* pm = means.mutable_data();
  double* pc = covs.mutable_data();
  double* pl = ll.mutable_data();
  int* pu = used.mutable_data();
  bind::check_steps(T, [&](Eigen::Index k) {
    detail::check_measurement(Y.row(k).transpose(), m, "Y");
    if (have_sight && (per_step || k == 0)) f.measurements().check_sight(S.row(k).transpose(), "sight");
  });
  {
    py::gil_scoped_release release;
    VecX y(m);
    VecXi s = VecXi::Zero(B);
    if (have_sight && S.rows() > 0) s = S.row(0).transpose();  // T = 0 with (T, B) sight: no row 0
    bind::run_steps(T, [&](Eigen::Index k) {
      y = Y.row(k).transpose();
      if (per_step) s = S.row(k).transpose();
      const StepResult r = f.step(y, have_sight ? &s : nullptr);
      Eigen::Map<Vec<N>>(pm + k * N) = f.mean();
      Eigen::Map<Eigen::Matrix<double, N, N, Eigen::RowMajor>>(pc + k * N * N) = f.cov();
      pl[k] = r.log_likelihood;
      pu[k] = r.rows_used;
    });
  }
  py::dict out;
  out["mean"] = means;
  out["cov"] = covs;
  out["log_likelihood"] = ll;
  out["rows_used"] = used;
  return out;
}

template <template <class> class F, class Cls>
void common_methods(Cls& c) {
  using A = AnyFilter<F>;
  c.def(
       "predict", [](A& a) { a.visit([](auto& f) { f.predict(); }); },
       "Prediction x = F x, P = F P F^T + Q; time advances by dt.")
      .def_property_readonly(
          "mean", [](const A& a) { return a.visit([](const auto& f) { return VecX(f.mean()); }); },
          "Posterior mean, shape (n,).")
      .def_property_readonly(
          "cov", [](const A& a) { return a.visit([](const auto& f) { return MatX(f.cov()); }); },
          "Posterior covariance, shape (n, n).")
      .def_property_readonly(
          "time", [](const A& a) { return a.visit([](const auto& f) { return f.time(); }); },
          "Time of the belief (s).")
      .def_property_readonly(
          "dim",
          [](const A& a) { return a.visit([](const auto& f) { return std::decay_t<decltype(f)>::kDim; }); })
      .def_property_readonly(
          "motion", [](const A& a) { return a.visit([](const auto& f) { return py::cast(f.motion()); }); },
          "The motion model (a copy).")
      .def(
          "belief",
          [](const A& a) {
            return a.visit([](const auto& f) { return py::make_tuple(VecX(f.mean()), MatX(f.cov())); });
          },
          "The belief as a tuple (mean (n,), cov (n, n)).");
  bind::def_set_belief<A>(c);
}

template <template <class> class F, class Cls>
void measurement_methods(Cls& c) {
  using A = AnyFilter<F>;
  c.def(
       "update",
       [](A& a, const bind::VecArg& y_in, const py::object& sight) {
         const VecX y = y_in.get("y");
         const auto s = sight_arg(sight);
         return a.visit([&](auto& f) { return f.update(y, s ? &*s : nullptr); });
       },
       py::arg("y"), py::arg("sight") = py::none(),
       "Update with y (m,) (NaN = missing row) and optional sight (B,) ints (default all LOS). Returns a "
       "StepResult with the predictive log-likelihood.")
      .def(
          "step",
          [](A& a, const bind::VecArg& y_in, const py::object& sight) {
            const VecX y = y_in.get("y");
            const auto s = sight_arg(sight);
            return a.visit([&](auto& f) { return f.step(y, s ? &*s : nullptr); });
          },
          py::arg("y"), py::arg("sight") = py::none(), "predict() then update(y, sight).")
      .def(
          "run",
          [](A& a, const bind::RowMatArg& Y_in, const py::object& sight) {
            const bind::RowMat Y = Y_in.get("Y");
            return a.visit([&](auto& f) {
              return run_batch(f, Y, sight, f.measurements().rows(), f.measurements().num_anchors());
            });
          },
          py::arg("Y"), py::arg("sight") = py::none(),
          "Runs step() over the rows of Y (T, m) in one call (GIL released). sight: None, (B,) or (T, B). "
          "Returns a dict with mean (T, n), cov (T, n, n), log_likelihood (T,), rows_used (T,).")
      .def_property_readonly(
          "measurements", [](const A& a) { return a.visit([](const auto& f) { return f.measurements(); }); });
}
/// The sigma-point settings of Ukf and UkfAugmented.
template <template <class> class F, class Cls>
void sigma_methods(Cls& c) {
  using A = AnyFilter<F>;
  c.def_property_readonly(
       "scheme", [](const A& a) { return a.visit([](const auto& f) { return f.scheme(); }); },
       "The sigma-point scheme (a copy).")
      .def_property_readonly(
          "weights", [](const A& a) { return a.visit([](const auto& f) { return f.weights(); }); },
          "The sigma-point weights of the update (a copy).");
}
}  // namespace

void define_module(py::module_& m) {
  py::enum_<NoiseForm>(m, "NoiseForm", "How a sigma-point filter treats the measurement noise.")
      .value("Additive", NoiseForm::kAdditive, "y = g(x) + n with n's exact mean and covariance (Ukf).")
      .value("Augmented", NoiseForm::kAugmented,
             "Noise inside the sigma points through each row's quantile (Huerta Table III, UkfAugmented).");
  py::class_<StepResult>(m, "StepResult", "What one update reports.")
      .def_readonly("log_likelihood", &StepResult::log_likelihood,
                    "log p(y_t | y_1:t-1, s), Gaussian predictive over the rows used (Huerta (III.2)).")
      .def_readonly("rows_used", &StepResult::rows_used, "Rows that were not NaN.")
      .def_readonly("status", &StepResult::status, "Worst Cholesky outcome of the step.")
      .def_readonly("jitter", &StepResult::jitter, "Diagonal added by the Cholesky fallback, if any.");

  {
    using A = AnyFilter<KfT>;
    py::class_<A> c(m, "Kf", "Linear Kalman filter y = H x + n, n ~ N(0, R).");
    c.def(py::init([](const py::object& motion, const bind::MatArg& H_in, const bind::MatArg& R_in,
                      const bind::VecArg& mean_in, const bind::MatArg& cov_in,
                      const bind::StrictArg<double>& t0_in) {
            const MatX H = H_in.get("H");
            const MatX R = R_in.get("R");
            const VecX mean = mean_in.get("mean");
            const MatX cov = cov_in.get("cov");
            const double t0 = t0_in.get("t0");
            return A(motion, mean, cov, [&](const auto& mo, const auto& g) {
              return Kf<std::decay_t<decltype(mo)>>(mo, H, R, g, t0);
            });
          }),
          py::arg("motion"), py::arg("H"), py::arg("R"), py::arg("mean"), py::arg("cov"), py::arg("t0") = 0.0,
          "motion: any motion model; H (m, n); R (m, m) SPD; initial belief N(mean, cov).");
    common_methods<KfT>(c);
    c.def_property_readonly(
         "H", [](const A& a) { return a.visit([](const auto& f) { return MatX(f.H()); }); }, "(m, n).")
        .def_property_readonly(
            "R", [](const A& a) { return a.visit([](const auto& f) { return MatX(f.R()); }); }, "(m, m).")
        .def_property_readonly("rows",
                               [](const A& a) { return a.visit([](const auto& f) { return f.rows(); }); })
        .def(
            "update",
            [](A& a, const bind::VecArg& y_in) {
              const VecX y = y_in.get("y");
              return a.visit([&](auto& f) { return f.update(y); });
            },
            py::arg("y"), "Update with y (m,), NaN = missing.")
        .def(
            "step",
            [](A& a, const bind::VecArg& y_in) {
              const VecX y = y_in.get("y");
              return a.visit([&](auto& f) { return f.step(y); });
            },
            py::arg("y"), "predict() then update(y).");
  }
  {
    using A = AnyFilter<EkfT>;
    py::class_<A> c(m, "Ekf", "Extended Kalman filter over a MeasurementStack (noise moments per sight).");
    c.def(py::init([](const py::object& motion, const MeasurementStack& meas, const bind::VecArg& mean_in,
                      const bind::MatArg& cov_in, const bind::StrictArg<double>& t0_in) {
            const VecX mean = mean_in.get("mean");
            const MatX cov = cov_in.get("cov");
            const double t0 = t0_in.get("t0");
            return A(motion, mean, cov, [&](const auto& mo, const auto& g) {
              return Ekf<std::decay_t<decltype(mo)>>(mo, meas, g, t0);
            });
          }),
          py::arg("motion"), py::arg("measurements"), py::arg("mean"), py::arg("cov"), py::arg("t0") = 0.0);
    common_methods<EkfT>(c);
    measurement_methods<EkfT>(c);
  }
  {
    using A = AnyFilter<UkfT>;
    py::class_<A> c(m, "Ukf",
                    "UKF with additive measurement noise (exact linear prediction; sigma points redrawn from "
                    "the predicted belief for the update).");
    c.def(py::init([](const py::object& motion, const MeasurementStack& meas, const bind::VecArg& mean_in,
                      const bind::MatArg& cov_in, const SigmaScheme& scheme,
                      const bind::StrictArg<double>& t0_in) {
            const VecX mean = mean_in.get("mean");
            const MatX cov = cov_in.get("cov");
            const double t0 = t0_in.get("t0");
            return A(motion, mean, cov, [&](const auto& mo, const auto& g) {
              return Ukf<std::decay_t<decltype(mo)>>(mo, meas, g, scheme, t0);
            });
          }),
          py::arg("motion"), py::arg("measurements"), py::arg("mean"), py::arg("cov"),
          py::arg_v("scheme", SigmaScheme::scaled(), "SigmaScheme.scaled()"), py::arg("t0") = 0.0);
    common_methods<UkfT>(c);
    measurement_methods<UkfT>(c);
    sigma_methods<UkfT>(c);
  }
  {
    using A = AnyFilter<UkfAugT>;
    py::class_<A> c(m, "UkfAugmented",
                    "UKF with the measurement noise in the sigma points through each distribution's quantile "
                    "map (Huerta Sec. V-A; Grisales eq. 29).");
    c.def(py::init([](const py::object& motion, const MeasurementStack& meas, const bind::VecArg& mean_in,
                      const bind::MatArg& cov_in, const SigmaScheme& scheme,
                      const bind::StrictArg<double>& t0_in) {
            const VecX mean = mean_in.get("mean");
            const MatX cov = cov_in.get("cov");
            const double t0 = t0_in.get("t0");
            return A(motion, mean, cov, [&](const auto& mo, const auto& g) {
              return UkfAugmented<std::decay_t<decltype(mo)>>(mo, meas, g, scheme, t0);
            });
          }),
          py::arg("motion"), py::arg("measurements"), py::arg("mean"), py::arg("cov"),
          py::arg_v("scheme", SigmaScheme::scaled(), "SigmaScheme.scaled()"), py::arg("t0") = 0.0);
    common_methods<UkfAugT>(c);
    measurement_methods<UkfAugT>(c);
    sigma_methods<UkfAugT>(c);
    c.def_property_readonly(
        "augmented_dim", [](const A& a) { return a.visit([](const auto& f) { return f.augmented_dim(); }); },
        "n + q: the state plus the measurement noise inputs in the sigma points (Huerta eq. 49).");
  }
}
}  // namespace nlosloc::bind_filters_cpp

void bind_filters(py::module_& m) { nlosloc::bind_filters_cpp::define_module(m); }
