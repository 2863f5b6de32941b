#pragma once
// The boundary between checking the input and computing with it (issue 24 §2: an internal failure is never
// reported as the user's error). Inside a computation on validated input, a value type built from a computed
// value (a model at a separation the continuation predicted, a law from fitted coefficients, options derived from
// others) refuses a NaN or an out-of-range value with InvalidParameter / InputError naming the *parameter* — which
// the CLI would report as bad input (exit 2). Across this boundary it becomes a NumericalFailure naming the
// computation (exit 1).
//
//   const auto r = computed("tapping orbit: the orbit search", [&] { return tapping::find_orbits(model, options); });
//
// Validate the input (models, options, sizes) before the boundary: everything thrown from inside is the
// computation's.
#include <string>
#include <utility>

#include "afmkit/core/error.hpp"

namespace afmkit {

template <class F>
decltype(auto) computed(const std::string& what, F&& compute) {
  try {
    return std::forward<F>(compute)();
  } catch (const InvalidParameter& e) {
    throw NumericalFailure(what + ": a value computed on the way is out of range (" + e.what() +
                           "); this is an internal failure, not an error in the input");
  } catch (const InputError& e) {
    throw NumericalFailure(what + ": a value computed on the way was refused (" + e.what() +
                           "); this is an internal failure, not an error in the input");
  }
}

}  // namespace afmkit
