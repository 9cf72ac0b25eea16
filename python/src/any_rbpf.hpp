#pragma once
/// \file any_rbpf.hpp
/// The Python classes Rbpf, ParticleFilter and Iukf of nlosloc.rbpf (bind_rbpf.cpp): each holds a
/// std::variant over the motion models of a non-copyable filter owned through unique_ptr (type erasure at
/// the filter level). In a header, so the Monte Carlo bindings (py_estimator.cpp) recognise them.
#include <pybind11/pybind11.h>

#include <memory>
#include <utility>
#include <variant>

#include "motion_arg.hpp"
#include "nlosloc/filters/iukf.hpp"
#include "nlosloc/rbpf/pf.hpp"
#include "nlosloc/rbpf/rbpf.hpp"

namespace nlosloc::bind {

/// A filter F<Motion> for any motion model in AnyMotion, owned through unique_ptr.
template <template <class> class F>
class AnyOwned {
 public:
  /// `make(motion)` returns a unique_ptr to the filter for the concrete motion type held by `motion`.
  template <class Make>
  AnyOwned(const pybind11::object& motion, Make&& make)
      : f_(std::visit([&](const auto& mo) -> V { return make(mo); }, to_motion(motion))) {}
  template <class Fn>
  decltype(auto) visit(Fn&& fn) {
    return std::visit([&](auto& p) -> decltype(auto) { return fn(*p); }, f_);
  }
  template <class Fn>
  decltype(auto) visit(Fn&& fn) const {
    return std::visit([&](const auto& p) -> decltype(auto) { return fn(*p); }, f_);
  }

 private:
  using V = std::variant<std::unique_ptr<F<ConstantVelocity2>>, std::unique_ptr<F<ConstantVelocity3>>,
                         std::unique_ptr<F<ConstantVelocityClock2>>,
                         std::unique_ptr<F<ConstantVelocityClock3>>, std::unique_ptr<F<TwoWayClock>>>;
  V f_;
};

template <class M>
using RbpfT = rbpf::Rbpf<M>;
template <class M>
using PfT = rbpf::ParticleFilter<M>;

/// The IUKF with the accessor names of the particle filters (estimate, covariance,
/// situation_probabilities), so the Python classes share them.
template <class M>
struct IukfBox : Iukf<M> {
  using Iukf<M>::Iukf;
  VecX estimate() const { return this->mean(); }
  MatX covariance() const { return this->cov(); }
  const MatX& situation_probabilities() const { return this->forward().probabilities(); }
};
template <class M>
using IukfBoxT = IukfBox<M>;

using AnyRbpf = AnyOwned<RbpfT>;
using AnyPf = AnyOwned<PfT>;
using AnyIukf = AnyOwned<IukfBoxT>;

}  // namespace nlosloc::bind
