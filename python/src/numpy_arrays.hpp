#pragma once
// NumPy arrays in and out of the bindings that take or return plain arrays of doubles (SI units).
#include <pybind11/numpy.h>

#include <algorithm>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"

namespace afmkit::python {

/// A 1-D array of doubles (converted from any numeric array, C order).
using Array = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

/// The values of a 1-D array; InvalidParameter naming `name` for any other shape.
inline std::vector<double> vector_of(const Array& a, const char* name) {
  if (a.ndim() != 1) throw InvalidParameter(name, std::string(name) + " must be a one-dimensional array");
  return {a.data(), a.data() + a.size()};
}

/// A new NumPy array holding `v`.
inline pybind11::array_t<double> array_of(const std::vector<double>& v) {
  pybind11::array_t<double> a(static_cast<pybind11::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

}  // namespace afmkit::python
