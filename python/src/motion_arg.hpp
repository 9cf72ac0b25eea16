#pragma once
/// \file motion_arg.hpp
/// The `motion` argument of the Python filter constructors: any motion class of nlosloc.models, held in
/// a variant so filters can be instantiated per concrete type (type erasure at the filter level), and the
/// (mean, cov) pair checked into a fixed-size Gaussian.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <string>
#include <type_traits>
#include <variant>

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

/// Binds set_belief(mean, cov, t=None) on a class wrapping FilterBase filters (A: a wrapper with visit()).
template <class A, class Cls>
void def_set_belief(Cls& c) {
  c.def(
      "set_belief",
      [](A& a, const VecX& mean, const MatX& cov, std::optional<double> t) {
        a.visit([&](auto& f) {
          constexpr int N = std::decay_t<decltype(f)>::kDim;
          const Gaussian<N> g = to_gaussian<N>(mean, cov, "mean", "cov");
          if (t)
            f.set_belief(g, *t);
          else
            f.set_belief(g);
        });
      },
      pybind11::arg("mean"), pybind11::arg("cov"), pybind11::arg("t") = pybind11::none(),
      "Replaces the belief (validated: finite mean, symmetric positive definite cov).");
}

}  // namespace nlosloc::bind
