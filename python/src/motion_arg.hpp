#pragma once
/// \file motion_arg.hpp
/// Arguments of the Python bindings: the `motion` of the filter constructors (any motion class of
/// nlosloc.models, held in a variant so filters can be instantiated per concrete type: type erasure at the
/// filter level), the (mean, cov) pair checked into a fixed-size Gaussian, and integer sight arrays.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>

#include "field_value.hpp"
#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/models/motion.hpp"

namespace nlosloc::bind {

using AnyMotion = std::variant<ConstantVelocity2, ConstantVelocity3, ConstantVelocityClock2,
                               ConstantVelocityClock3, TwoWayClock>;

/// Casts a Python motion object; ValueError naming `motion` otherwise.
inline AnyMotion to_motion(const pybind11::object& o) {
  if (pybind11::isinstance<ConstantVelocity2>(o)) return o.cast<ConstantVelocity2>();
  if (pybind11::isinstance<ConstantVelocity3>(o)) return o.cast<ConstantVelocity3>();
  if (pybind11::isinstance<ConstantVelocityClock2>(o)) return o.cast<ConstantVelocityClock2>();
  if (pybind11::isinstance<ConstantVelocityClock3>(o)) return o.cast<ConstantVelocityClock3>();
  if (pybind11::isinstance<TwoWayClock>(o)) return o.cast<TwoWayClock>();
  throw std::invalid_argument(
      "motion: expected ConstantVelocity2, ConstantVelocity3, ConstantVelocityClock2, ConstantVelocityClock3 "
      "or TwoWayClock, got " +
      std::string(pybind11::str(pybind11::type::of(o).attr("__name__"))));
}

/// Gaussian<N> from Python arrays, shapes checked under the given argument names.
template <int N>
Gaussian<N> to_gaussian(const VecX& mean, const MatX& cov, const char* mname = "mean",
                        const char* cname = "cov") {
  detail::ensure_shape(mean, N, 1, mname);
  detail::ensure_shape(cov, N, N, cname);
  return Gaussian<N>(mean, cov);
}

/// to_gaussian, and the belief checked by Gaussian::validate (finite mean, symmetric positive definite cov),
/// each error naming the Python argument.
template <int N>
Gaussian<N> to_belief(const VecX& mean, const MatX& cov, const char* mname = "mean",
                      const char* cname = "cov") {
  Gaussian<N> g = to_gaussian<N>(mean, cov, mname, cname);
  g.validate(mname, cname);
  return g;
}

/// Binds set_belief(mean, cov, t=None) on a class wrapping FilterBase filters (A: a wrapper with visit()).
template <class A, class Cls>
void def_set_belief(Cls& c) {
  c.def(
      "set_belief",
      [](A& a, const VecArg& mean, const MatArg& cov, const std::optional<bind::StrictArg<double>>& t_in) {
        const std::optional<double> t = bind::optional_get(t_in, "t");
        a.visit([&](auto& f) {
          constexpr int N = std::decay_t<decltype(f)>::kDim;
          const Gaussian<N> g = to_gaussian<N>(mean.get("mean"), cov.get("cov"), "mean", "cov");
          if (t)
            f.set_belief(g, *t);
          else
            f.set_belief(g);
        });
      },
      pybind11::arg("mean"), pybind11::arg("cov"), pybind11::arg("t") = pybind11::none(),
      "Replaces the belief (validated: finite mean, symmetric positive definite cov).");
}

/// Sight conditions (or any integer labels) from a 1-D or 2-D Python array, row-major (1-D: one row);
/// *ndim receives the array's dimensions. Values must be integers (floats with integral values are
/// accepted): an implicit cast would turn 0.5 into condition 0 without a word. The callee checks the
/// range and the shape.
inline Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> to_int_rows(
    const pybind11::handle& o, const char* name, int* ndim) {
  namespace py = pybind11;
  reject_non_real(o, name);
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(o);
  if (!a || a.ndim() < 1 || a.ndim() > 2)
    throw std::invalid_argument(std::string(name) + ": expected an integer array of 1 or 2 dimensions");
  *ndim = static_cast<int>(a.ndim());
  const Eigen::Index rows = a.ndim() == 2 ? a.shape(0) : 1;
  const Eigen::Index cols = a.shape(a.ndim() - 1);
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> out(rows, cols);
  const double* d = a.data();
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < cols; ++c) {
      const double v = d[r * cols + c];
      if (!(std::floor(v) == v) || std::fabs(v) > 2147483647.0)
        throw std::invalid_argument(std::string(name) + ": expected integers, got " + std::to_string(v) +
                                    " at " +
                                    (*ndim == 2 ? "(" + std::to_string(r) + ", " + std::to_string(c) + ")"
                                                : "entry " + std::to_string(c)));
      out(r, c) = static_cast<int>(v);
    }
  return out;
}

/// Binds a method of T taking one vector (z, o, ...) through VecArg, so its errors name `name`.
template <class T, auto Method>
auto vector_method(const char* name) {
  return [name](T& self, const VecArg& v) { return (self.*Method)(v.get(name)); };
}

/// A (B,) vector of sight conditions (to_int_rows; a 1-D array required).
inline VecXi to_sight(const pybind11::handle& o, const char* name = "sight") {
  int ndim = 0;
  const auto m = to_int_rows(o, name, &ndim);
  if (ndim != 1) throw std::invalid_argument(std::string(name) + ": expected a 1-D integer array (B,)");
  return m.row(0).transpose();
}

}  // namespace nlosloc::bind
