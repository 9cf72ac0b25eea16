#pragma once
/// \file params_field.hpp
/// Read-write numpy properties for the fixed-size Eigen fields of the scenario parameter structs
/// (H1Params.start, K1Params.anchors, ...): the getter returns a copy (a 1-D array for a vector), the
/// setter checks the shape and names the field ("K1Params.anchors: expected shape ...").
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <string>
#include <type_traits>
#include <utility>

#include "nlosloc/core/types.hpp"

namespace nlosloc::bind {

template <class M>
struct MemberOf;
template <class P, class T>
struct MemberOf<T P::*> {
  using Owner = P;
  using Type = T;
};

/// Binds `Field` (a pointer to a fixed-size Eigen member) as property `name` of class `c`.
template <auto Field, class C>
void fixed_field(C& c, const char* name, std::string qualified, const char* doc) {
  using P = typename MemberOf<decltype(Field)>::Owner;
  using T = typename MemberOf<decltype(Field)>::Type;
  using Py = std::conditional_t<T::ColsAtCompileTime == 1, VecX, MatX>;  // (n,) for vectors
  c.def_property(
      name, [](const P& p) { return Py(p.*Field); },
      [qualified = std::move(qualified)](P& p, const Py& v) {
        detail::ensure_shape(v, T::RowsAtCompileTime, T::ColsAtCompileTime, qualified.c_str());
        p.*Field = v;
      },
      doc);
}

}  // namespace nlosloc::bind
