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

/// Binds a method of T taking one vector (z, o, ...) through VecArg, so its errors name `name`.
template <class T, auto Method>
auto vector_method(const char* name) {
  return [name](T& self, const VecArg& v) { return (self.*Method)(v.get(name)); };
}

}  // namespace nlosloc::bind
