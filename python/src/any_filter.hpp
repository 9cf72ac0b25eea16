#pragma once
/// \file any_filter.hpp
/// The Python filter classes of nlosloc.filters (bind_filters.cpp): one class per filter family holding a
/// std::variant over the motion models (type erasure at the filter level, so nothing virtual runs per
/// sigma point). In a header, so the Monte Carlo bindings (py_estimator.cpp) recognise and copy them.
#include <pybind11/pybind11.h>

#include <type_traits>
#include <utility>
#include <variant>

#include "motion_arg.hpp"
#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/filters/kf.hpp"
#include "nlosloc/filters/ukf.hpp"

namespace nlosloc::bind {

/// A filter of family F over any motion model in AnyMotion.
template <template <class> class F>
class AnyFilter {
 public:
  /// `make(motion, initial)` builds the filter for the concrete motion type held by `motion`.
  template <class Make>
  AnyFilter(const pybind11::object& motion_obj, const VecX& mean, const MatX& cov, Make&& make)
      : f_(std::visit(
            [&](const auto& mo) -> V {
              using M = std::decay_t<decltype(mo)>;
              return make(mo, to_gaussian<M::kDim>(mean, cov, "mean", "cov"));
            },
            to_motion(motion_obj))) {}

  template <class Fn>
  decltype(auto) visit(Fn&& fn) {
    return std::visit(std::forward<Fn>(fn), f_);
  }
  template <class Fn>
  decltype(auto) visit(Fn&& fn) const {
    return std::visit(std::forward<Fn>(fn), f_);
  }

 private:
  using V = std::variant<F<ConstantVelocity2>, F<ConstantVelocity3>, F<ConstantVelocityClock2>,
                         F<ConstantVelocityClock3>, F<TwoWayClock>>;
  V f_;
};

template <class M>
using KfT = Kf<M>;
template <class M>
using EkfT = Ekf<M>;
template <class M>
using UkfT = Ukf<M>;
template <class M>
using UkfAugT = UkfAugmented<M>;

}  // namespace nlosloc::bind
