#pragma once
/// \file params_field.hpp
/// Read-write properties for the fields of the option and parameter structs, in place of def_readwrite,
/// whose setter converts as pybind11 does (None to False, True to 1.0) and names no field when it refuses.
/// - field_get / field_set: scalar, enum and struct fields; the setter converts by field_value
///   (field_value.hpp) and names the field ("QpBiasEkfOptions.gamma: expected a real number, got ..."),
///   and assigns only a converted value, so a refused one leaves the struct as it was.
/// - fixed_field: the fixed-size Eigen fields of the scenario parameters (H1Params.start, K1Params.anchors,
///   ...): the getter returns a copy (a 1-D array for a vector), the setter checks the shape and names the
///   field ("K1Params.anchors: expected shape ...").
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <string>
#include <type_traits>
#include <utility>

#include "field_value.hpp"
#include "nlosloc/core/types.hpp"

namespace nlosloc::bind {

template <class M>
struct MemberOf;
template <class P, class T>
struct MemberOf<T P::*> {
  using Owner = P;
  using Type = T;
};

/// The getter of `Field` for def_property: a reference, which def_property returns with
/// reference_internal as def_readwrite does (opts.noise.sigma0 = 2 changes opts).
template <auto Field>
auto field_get() {
  using P = typename MemberOf<decltype(Field)>::Owner;
  using T = typename MemberOf<decltype(Field)>::Type;
  return [](const P& p) -> const T& { return p.*Field; };
}

/// The setter of `Field`, bound as property `name`: errors begin with "<P's Python class>.<name>: ".
template <auto Field>
auto field_set(const char* name) {
  using P = typename MemberOf<decltype(Field)>::Owner;
  using T = typename MemberOf<decltype(Field)>::Type;
  return [name](P& p, const StrictArg<T>& v) {
    const std::string what =
        std::string(pybind11::str(pybind11::type::of<P>().attr("__name__"))) + "." + name;
    T value = field_value<T>(v.obj, what);
    p.*Field = std::move(value);
  };
}

/// Binds `Field` (a pointer to a fixed-size Eigen member) as property `name` of class `c`.
template <auto Field, class C>
void fixed_field(C& c, const char* name, std::string qualified, const char* doc) {
  using P = typename MemberOf<decltype(Field)>::Owner;
  using T = typename MemberOf<decltype(Field)>::Type;
  using Py = std::conditional_t<T::ColsAtCompileTime == 1, VecX, MatX>;  // (n,) for vectors
  c.def_property(
      name, [](const P& p) { return Py(p.*Field); },
      [qualified = std::move(qualified)](P& p, const StrictArg<Py>& in) {
        const Py v = in.get(qualified.c_str());
        detail::ensure_shape(v, T::RowsAtCompileTime, T::ColsAtCompileTime, qualified.c_str());
        p.*Field = v;
      },
      doc);
}

}  // namespace nlosloc::bind
