#pragma once
/// \file field_value.hpp
/// Strict conversion of one Python value to a C++ scalar or registered type, with errors that name the
/// receiver: the option and parameter fields (`QpBiasEkfOptions.gamma`), and through StrictArg the time
/// arguments (`t0`), sizes (`n`), and through strict_init, strict_fn and strict_method the number and bool
/// parameters of constructors and model functions (`Normal(mean, std)`, `ConstantVelocity2(dt, sigma2)`,
/// `MeasurementStack.add_toa(anchor, noise)`); and of float vectors and matrices (to_vector, to_matrix:
/// measurements `y`, `o`, `z`, means, covariances, anchors, batches), whose bool, complex or str arrays
/// numpy would cast to float64 without an error.
/// pybind11's own casters, used by def_readwrite and plain double/int arguments, take None and 0.5 as
/// False for a bool field, True as 1.0 for a float, and refuse a wrong type with "incompatible function
/// arguments" (TypeError) that shows the signature but not the field. Here a bool is a bool (True, False,
/// numpy.bool_), a real number is anything with __float__ except bool, complex and str, and an integer is
/// anything with __index__ except bool, in the range of the C++ type (ValueError otherwise). A 0-d numpy
/// array is read as its scalar; any other array is refused.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

#include "nlosloc/core/types.hpp"

namespace nlosloc::bind {

namespace field_detail {

namespace py = pybind11;

/// "0.5 (float)": the value and its type, for the messages.
inline std::string describe(py::handle v) {
  return std::string(py::repr(v)) + " (" + std::string(py::str(py::type::of(v).attr("__name__"))) + ")";
}

/// Whether v is an instance of numpy's scalar type `name` (bool_, complexfloating).
inline bool is_numpy(py::handle v, const char* name) {
  const py::object np = py::module_::import("numpy");
  return py::isinstance(v, np.attr(name));
}

/// A 0-d array as its Python scalar, any other object as it is; an array of 1 or more dimensions is refused.
inline py::object unwrap_0d(py::handle v, const std::string& what, const char* expected) {
  if (!py::isinstance<py::array>(v)) return py::reinterpret_borrow<py::object>(v);
  const auto a = py::reinterpret_borrow<py::array>(v);
  if (a.ndim() != 0)
    throw py::type_error(what + ": expected " + expected + ", got a " + std::to_string(a.ndim()) +
                         "-D array");
  return a.attr("item")();
}

inline bool is_bool(py::handle v) { return PyBool_Check(v.ptr()) || is_numpy(v, "bool_"); }

inline bool to_bool(py::handle v0, const std::string& what) {
  const py::object v = unwrap_0d(v0, what, "a bool (True or False)");
  if (!is_bool(v)) throw py::type_error(what + ": expected a bool (True or False), got " + describe(v));
  return PyObject_IsTrue(v.ptr()) == 1;
}

inline double to_real(py::handle v0, const std::string& what) {
  const py::object v = unwrap_0d(v0, what, "a real number");
  // str has no __float__ slot; complex and numpy's complex scalars have one that drops the imaginary part.
  const auto* num = Py_TYPE(v.ptr())->tp_as_number;
  const bool has_float = num != nullptr && (num->nb_float != nullptr || num->nb_index != nullptr);
  if (!has_float || is_bool(v) || PyComplex_Check(v.ptr()) || is_numpy(v, "complexfloating"))
    throw py::type_error(what + ": expected a real number, got " + describe(v));
  const double d = PyFloat_AsDouble(v.ptr());
  if (d == -1.0 && PyErr_Occurred()) {  // an int beyond a double's range (OverflowError)
    PyErr_Clear();
    throw py::value_error(what + ": expected a real number within the range of a double, got " + describe(v));
  }
  return d;
}

template <class T>
T to_integer(py::handle v0, const std::string& what) {
  constexpr auto lo = std::numeric_limits<T>::min();
  constexpr auto hi = std::numeric_limits<T>::max();
  const std::string range = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  const py::object v = unwrap_0d(v0, what, "an integer");
  if (is_bool(v) || !PyIndex_Check(v.ptr()))  // a float has no __index__: 2.0 is refused, as in range()
    throw py::type_error(what + ": expected an integer, got " + describe(v));
  const auto i = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
  if (!i) throw py::error_already_set();
  int overflow = 0;
  const long long s = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow == 0 && s == -1 && PyErr_Occurred()) throw py::error_already_set();
  bool fits = false;
  T out{};
  if (overflow == 0) {
    fits = std::is_signed_v<T> ? (s >= static_cast<long long>(lo) && s <= static_cast<long long>(hi))
                               : (s >= 0 && static_cast<unsigned long long>(s) <= hi);
    out = static_cast<T>(s);
  } else if (overflow > 0 && !std::is_signed_v<T>) {  // above 2**63 - 1: within 2**64 - 1?
    const unsigned long long u = PyLong_AsUnsignedLongLong(i.ptr());
    if (u == static_cast<unsigned long long>(-1) && PyErr_Occurred()) {
      PyErr_Clear();
    } else {
      fits = u <= hi;
      out = static_cast<T>(u);
    }
  }
  if (!fits) throw py::value_error(what + ": expected " + range + ", got " + std::string(py::repr(i)));
  return out;
}

}  // namespace field_detail

/// A C-contiguous float64 array.
using RealArray = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

/// o as a RealArray: numpy's asarray, read once, then cast to float64 (no copy when it already is one); a
/// null array when numpy cannot read o as numbers (the caller names it). Refused, named, when numpy reads
/// it as an array of a kind the cast would take without a word: bool (True as 1.0), complex (the imaginary
/// part dropped; numpy only warns), str and bytes (parsed), datetimes, structured records. Float, integer
/// and object arrays (whose elements numpy converts one by one) pass.
inline RealArray real_array(const pybind11::handle& o, const char* name) {
  namespace py = pybind11;
  py::object raw = py::reinterpret_borrow<py::object>(o);
  if (!py::isinstance<py::array>(o)) {
    const bool seq =
        !o.is_none() && !PyUnicode_Check(o.ptr()) && !PyBytes_Check(o.ptr()) && PySequence_Check(o.ptr());
    if (seq) raw = py::array::ensure(o);  // np.asarray: the dtype numpy infers ([True, False]: bool)
    // None, a str, a scalar, not array-like: numpy's cast decides
    if (!seq || !raw) return RealArray::ensure(o);
  }
  const char kind = py::reinterpret_borrow<py::array>(raw).dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'O') {
    const char* what = kind == 'b'   ? "bool"
                       : kind == 'c' ? "complex"
                       : kind == 'U' ? "str"
                       : kind == 'S' ? "bytes"
                                     : "non-numeric";
    throw std::invalid_argument(std::string(name) + ": expected real values, got a " + what + " array");
  }
  return RealArray::ensure(raw);
}

namespace field_detail {
/// o as a C-contiguous float64 array of `ndim` dimensions, or std::invalid_argument naming it ("expected a
/// 1-D float array, got None"); pybind11's Eigen caster raised "incompatible function arguments" or cast.
inline RealArray float_array(const pybind11::handle& o, const char* name, int ndim) {
  namespace py = pybind11;
  const std::string expected =
      std::string(name) + ": expected a " + std::to_string(ndim) + "-D float array, got ";
  if (o.is_none())  // numpy reads None as a 0-d NaN array
    throw std::invalid_argument(expected + "None");
  const RealArray a = real_array(o, name);
  if (!a || a.ndim() != ndim)
    throw std::invalid_argument(expected + (a ? std::to_string(a.ndim()) + " dimensions"
                                              : std::string(py::str(py::type::of(o).attr("__name__")))));
  return a;
}
}  // namespace field_detail

/// A float vector from a Python object (a 1-D array or sequence of numbers), or std::invalid_argument
/// naming it. The callee checks the size and values.
inline VecX to_vector(const pybind11::handle& o, const char* name) {
  const auto a = field_detail::float_array(o, name, 1);
  return Eigen::Map<const VecX>(a.data(), a.shape(0));
}

/// A float matrix (M: MatX or a row-major matrix) from a 2-D array or nested sequence, or
/// std::invalid_argument naming it. pybind11's caster read a 1-D array as a column: refused here, since
/// for every matrix argument of the bindings (covariances, anchors, batches of rows) it is a mistake.
template <class M = MatX>
M to_matrix(const pybind11::handle& o, const char* name) {
  const auto a = field_detail::float_array(o, name, 2);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  return M(Eigen::Map<const RowMajor>(a.data(), a.shape(0), a.shape(1)));
}

/// Sight conditions (or any integer labels) from a 1-D or 2-D Python array, row-major (1-D: one row);
/// *ndim receives the array's dimensions. Values must be integers (floats with integral values are
/// accepted): an implicit cast would turn 0.5 into condition 0 without a word. The callee checks the
/// range and the shape.
inline Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> to_int_rows(
    const pybind11::handle& o, const char* name, int* ndim) {
  namespace py = pybind11;
  const RealArray a = real_array(o, name);
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

/// A (B,) vector of sight conditions (to_int_rows; a 1-D array required).
inline VecXi to_sight(const pybind11::handle& o, const char* name = "sight") {
  int ndim = 0;
  const auto m = to_int_rows(o, name, &ndim);
  if (ndim != 1) throw std::invalid_argument(std::string(name) + ": expected a 1-D integer array (B,)");
  return m.row(0).transpose();
}

/// A list of matrices from a sequence of 2-D arrays or one 3-D array, each read by to_matrix under its own
/// name (covs[i]).
inline std::vector<MatX> to_matrices(const pybind11::handle& o, const char* name) {
  namespace py = pybind11;
  if (!PySequence_Check(o.ptr()) || PyUnicode_Check(o.ptr()) || PyBytes_Check(o.ptr()))
    throw std::invalid_argument(std::string(name) +
                                ": expected a sequence of 2-D float arrays or one 3-D array, got " +
                                std::string(py::str(py::type::of(o).attr("__name__"))));
  const auto seq = py::reinterpret_borrow<py::sequence>(o);
  std::vector<MatX> out;
  out.reserve(seq.size());
  for (std::size_t i = 0; i < seq.size(); ++i)
    out.push_back(to_matrix(seq[i], (std::string(name) + "[" + std::to_string(i) + "]").c_str()));
  return out;
}

/// `v` as a T, or TypeError/ValueError beginning with `what` (the field or argument name). Scalars follow
/// the rules of the file comment, a VecX is to_vector's, a MatX or row-major matrix to_matrix's, integer
/// vectors and matrices to_int_rows', a list of matrices to_matrices'; any other T
/// (an enum, a struct) is pybind11's cast, its failure named.
template <class T>
T field_value(pybind11::handle v, const std::string& what) {
  namespace py = pybind11;
  if constexpr (std::is_same_v<T, bool>) {
    return field_detail::to_bool(v, what);
  } else if constexpr (std::is_floating_point_v<T>) {
    return static_cast<T>(field_detail::to_real(v, what));
  } else if constexpr (std::is_integral_v<T>) {
    return field_detail::to_integer<T>(v, what);
  } else if constexpr (std::is_same_v<T, VecX>) {
    return to_vector(v, what.c_str());
  } else if constexpr (std::is_same_v<T, MatX> ||
                       std::is_same_v<
                           T, Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>) {
    return to_matrix<T>(v, what.c_str());
  } else if constexpr (std::is_same_v<T, VecXi>) {
    return to_sight(v, what.c_str());
  } else if constexpr (std::is_same_v<T, Eigen::MatrixXi>) {
    int ndim = 0;
    Eigen::MatrixXi m = to_int_rows(v, what.c_str(), &ndim);
    if (ndim != 2) throw std::invalid_argument(what + ": expected a 2-D integer array");
    return m;
  } else if constexpr (std::is_same_v<T, std::vector<MatX>>) {
    return to_matrices(v, what.c_str());
  } else {
    try {
      return py::cast<T>(v);
    } catch (const py::cast_error&) {
      // py::type::of<T> is for classes only; the registry also knows the enums of py::enum_.
      const auto* info = py::detail::get_type_info(typeid(T));
      const std::string name =
          info != nullptr
              ? std::string(py::str(py::handle(reinterpret_cast<PyObject*>(info->type)).attr("__name__")))
              : std::string(py::detail::make_caster<T>::name.text);
      throw py::type_error(what + ": expected " + name + ", got " + field_detail::describe(v));
    }
  }
}

/// An argument of type T read by field_value when the function reads it (get), so its errors name it. The
/// caster takes any object, except in the first, exact pass over an overloaded function's overloads (see
/// the caster). The signature shows T's Python type.
template <class T>
struct StrictArg {
  pybind11::object obj;
  T get(const char* name) const { return field_value<T>(obj, name); }
};

/// A float vector argument, converted by to_vector (field_value.hpp) when the function reads it (get), so
/// a wrong shape or type raises ValueError naming the argument. pybind11's Eigen caster refuses it with a
/// TypeError about the whole signature ("incompatible function arguments"), e.g. for a (1, m) row sliced
/// from a (T, m) array. In an overloaded function it yields, in pybind11's first pass, to an overload
/// that takes the value exactly (see StrictArg's caster).
using VecArg = StrictArg<VecX>;
/// A float matrix argument, converted by to_matrix the same way (bool, complex or str arrays, None and
/// arrays of other than 2 dimensions refused, named): covariances, anchors, gains.
using MatArg = StrictArg<MatX>;
/// A row-major float matrix argument (to_matrix): the (T, m) batches of run().
using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatArg = StrictArg<RowMat>;

namespace field_detail {
template <class T, class... A, std::size_t... I>
auto strict_init(std::array<const char*, sizeof...(A)> names, std::index_sequence<I...>) {
  return pybind11::init([names](const StrictArg<A>&... a) { return T(a.get(names[I])...); });
}
}  // namespace field_detail

/// py::init of T from its constructor's arguments A..., each converted by StrictArg under its name:
/// strict_init<Normal, double, double>("mean", "std"). T's constructor checks the values.
template <class T, class... A, class... Names>
auto strict_init(Names... names) {
  static_assert(sizeof...(A) == sizeof...(Names), "one name per argument");
  return field_detail::strict_init<T, A...>({names...}, std::index_sequence_for<A...>{});
}

namespace field_detail {
/// True for the parameters a strict wrapper reads through StrictArg: bools, numbers, and float vectors
/// and matrices (to_vector / to_matrix: a wrong shape or dtype is named).
template <class A>
inline constexpr bool is_strict_v =
    std::is_arithmetic_v<std::decay_t<A>> || std::is_same_v<std::decay_t<A>, VecX> ||
    std::is_same_v<std::decay_t<A>, MatX>;

/// The parameter type of a strict wrapper for a parameter A of the wrapped function: a StrictArg for a
/// bool, number, VecX or MatX, A itself otherwise (distributions, generators, enums keep pybind11's
/// casters).
template <class A>
using strict_param = std::conditional_t<is_strict_v<A>, StrictArg<std::decay_t<A>>, A>;

template <class A, class V>
decltype(auto) strict_value(V&& v, const char* name) {
  if constexpr (is_strict_v<A>) {
    return v.get(name);
  } else {
    return std::forward<V>(v);
  }
}

template <class R, class... A, std::size_t... I>
auto strict_fn(R (*f)(A...), std::array<const char*, sizeof...(A)> names, std::index_sequence<I...>) {
  return [f, names](strict_param<A>... a) -> R { return f(strict_value<A>(a, names[I])...); };
}

template <class R, class C, class... A, std::size_t... I>
auto strict_method(R (C::*f)(A...), std::array<const char*, sizeof...(A)> names, std::index_sequence<I...>) {
  return
      [f, names](C& self, strict_param<A>... a) -> R { return (self.*f)(strict_value<A>(a, names[I])...); };
}
}  // namespace field_detail

/// The free function f with its bool, number, VecX and MatX parameters read by StrictArg under their names
/// (in the order of f's parameters, one per parameter): strict_fn(&speed_transition_memoryless,
/// "mean_los", "mean_nlos"). Other parameters keep pybind11's casters.
template <class R, class... A, class... Names>
auto strict_fn(R (*f)(A...), Names... names) {
  static_assert(sizeof...(A) == sizeof...(Names), "one name per parameter");
  return field_detail::strict_fn(f, {names...}, std::index_sequence_for<A...>{});
}

/// strict_fn for a non-const member function (the object is the first argument, as in py::class_::def).
template <class R, class C, class... A, class... Names>
auto strict_method(R (C::*f)(A...), Names... names) {
  static_assert(sizeof...(A) == sizeof...(Names), "one name per parameter");
  return field_detail::strict_method(f, {names...}, std::index_sequence_for<A...>{});
}

/// An optional StrictArg's value (nullopt for None).
template <class T>
std::optional<T> optional_get(const std::optional<StrictArg<T>>& a, const char* name) {
  if (!a) return std::nullopt;
  return a->get(name);
}

}  // namespace nlosloc::bind

namespace pybind11::detail {

template <class T>
struct type_caster<nlosloc::bind::StrictArg<T>> {
  PYBIND11_TYPE_CASTER(nlosloc::bind::StrictArg<T>, make_caster<T>::name);
  bool load(handle src, bool convert) {
    if (!src) return false;
    // convert is false only in the first pass over an overloaded function's overloads: take only a value
    // that converts, so an overload listed later can take the rest (QualityModel.log_likelihood's scalar
    // form takes numpy.float32(0.5), run_k2_study's K2 form its scenario). In the second pass, and for a
    // function without overloads, take any object: get() then raises the error that names the argument.
    if (!convert) {
      try {
        (void)nlosloc::bind::field_value<T>(src, "");
      } catch (const std::exception&) {
        return false;
      }
    }
    value.obj = reinterpret_borrow<object>(src);
    return true;
  }
  static handle cast(const nlosloc::bind::StrictArg<T>& v, return_value_policy, handle) {
    return v.obj.inc_ref();
  }
};

}  // namespace pybind11::detail
