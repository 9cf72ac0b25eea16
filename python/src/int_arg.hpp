#pragma once
/// \file int_arg.hpp
/// Unsigned 64-bit arguments (seeds, run indices, counts). pybind11's own std::uint64_t caster refuses a
/// negative int with "incompatible function arguments" (TypeError), which names neither the argument nor the
/// range. UInt64Arg accepts any object with __index__ (int, numpy integers) and keeps out-of-range values,
/// so the function can raise ValueError naming the argument: get("seed"). Also the shared `steps` check.
#include <pybind11/pybind11.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "field_value.hpp"

namespace nlosloc::bind {

struct UInt64Arg {
  std::uint64_t value = 0;
  bool in_range = true;
  std::string repr;  ///< the Python value, for the message when out of range

  UInt64Arg() = default;
  UInt64Arg(std::uint64_t v) : value(v) {}  // NOLINT(google-explicit-constructor): defaults of py::arg

  /// The value; ValueError "<name>: expected an integer in [0, 2**64 - 1], got <repr>" when out of range.
  std::uint64_t get(const char* name) const {
    if (!in_range)
      throw pybind11::value_error(std::string(name) + ": expected an integer in [0, 2**64 - 1], got " + repr);
    return value;
  }
};

/// An index argument (a particle or row i): any Python integer. The callee checks the range; one beyond
/// the range of int raises IndexError naming the argument when read (get), where pybind11's int caster
/// raised "incompatible function arguments" (TypeError) for 2**31.
struct IndexArg {
  int value = 0;
  bool in_range = true;
  std::string repr;  ///< the Python value, for the message when beyond int

  int get(const char* name) const {
    if (!in_range)
      throw pybind11::index_error(std::string(name) + ": expected an index within the range of int, got " +
                                  repr);
    return value;
  }
};

/// The `steps` argument of the sim functions: None is the scenario's default (0 inside C++); a number must
/// be >= 1, since 0 given explicitly is a mistake rather than a request for the default.
inline int steps_arg(const std::optional<nlosloc::bind::StrictArg<int>>& steps_in) {
  const std::optional<int> steps = optional_get(steps_in, "steps");  // an int, not True (field_value.hpp)
  if (steps && *steps < 1)
    throw std::invalid_argument("steps: expected >= 1 (None: the scenario's default), got " +
                                std::to_string(*steps));
  return steps.value_or(0);
}

}  // namespace nlosloc::bind

namespace pybind11::detail {

template <>
struct type_caster<nlosloc::bind::UInt64Arg> {
  PYBIND11_TYPE_CASTER(nlosloc::bind::UInt64Arg, const_name("int"));

  bool load(handle src, bool /*convert*/) {
    if (!src) return false;
    // Integers only: a float or bool seed is a TypeError, as for pybind11's int arguments.
    if (PyFloat_Check(src.ptr()) || PyBool_Check(src.ptr())) return false;
    object idx = reinterpret_steal<object>(PyNumber_Index(src.ptr()));
    if (!idx) {
      PyErr_Clear();
      return false;
    }
    const unsigned long long v = PyLong_AsUnsignedLongLong(idx.ptr());
    if (v == static_cast<unsigned long long>(-1) && PyErr_Occurred()) {
      PyErr_Clear();  // negative or >= 2**64: kept for the function to name
      value.in_range = false;
      value.value = 0;
      value.repr = pybind11::repr(src).cast<std::string>();
      return true;
    }
    value = nlosloc::bind::UInt64Arg(static_cast<std::uint64_t>(v));
    return true;
  }

  static handle cast(const nlosloc::bind::UInt64Arg& v, return_value_policy, handle) {
    return PyLong_FromUnsignedLongLong(static_cast<unsigned long long>(v.value));
  }
};

template <>
struct type_caster<nlosloc::bind::IndexArg> {
  PYBIND11_TYPE_CASTER(nlosloc::bind::IndexArg, const_name("int"));

  bool load(handle src, bool /*convert*/) {
    // a float or bool index is a TypeError, as for int
    if (!src || PyFloat_Check(src.ptr()) || PyBool_Check(src.ptr())) return false;
    object idx = reinterpret_steal<object>(PyNumber_Index(src.ptr()));
    if (!idx) {
      PyErr_Clear();
      return false;
    }
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(idx.ptr(), &overflow);
    if (overflow == 0 && v == -1 && PyErr_Occurred()) {
      PyErr_Clear();
      return false;
    }
    value = nlosloc::bind::IndexArg{};
    if (overflow != 0 || v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
      value.in_range = false;
      value.repr = pybind11::repr(idx).cast<std::string>();
    } else {
      value.value = static_cast<int>(v);
    }
    return true;
  }
};

}  // namespace pybind11::detail
