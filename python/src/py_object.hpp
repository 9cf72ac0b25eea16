#pragma once
/// \file py_object.hpp
/// Python objects held from C++ (the Monte Carlo runner's Python estimators, a box-QP solver written in
/// Python) and the description of a wrong result in their error messages.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <utility>

namespace nlosloc::bind {

/// A Python object shared by C++ threads (the runner's workers): copying the pointer touches no Python
/// reference count, and the last owner drops the object with the GIL taken, on whatever thread it is.
using SharedObject = std::shared_ptr<pybind11::object>;
inline SharedObject share(pybind11::object o) {
  return SharedObject(new pybind11::object(std::move(o)), [](pybind11::object* p) {
    pybind11::gil_scoped_acquire gil;
    delete p;
  });
}

/// "an array of shape (a, b)" or "an object of type T", for the messages.
inline std::string describe(const pybind11::handle& r) {
  if (pybind11::isinstance<pybind11::array>(r)) {
    const auto a = pybind11::reinterpret_borrow<pybind11::array>(r);
    std::string s = "an array of shape (";
    for (pybind11::ssize_t i = 0; i < a.ndim(); ++i) s += (i > 0 ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
  }
  return std::string("an object of type ") +
         pybind11::str(pybind11::type::handle_of(r).attr("__name__")).cast<std::string>();
}

/// describe(r), and the shape numpy read it as when r is not an array (a list, None: a 0-d NaN).
inline std::string describe(const pybind11::handle& r, const pybind11::array& as) {
  if (!as || pybind11::isinstance<pybind11::array>(r)) return describe(r);
  return describe(r) + ", read as " + describe(as);
}

}  // namespace nlosloc::bind
