#pragma once
// Error types shared by every domain.
//   InvalidParameter : bad input (the CLI exits with status 2)
//   NumericalFailure : a solver did not converge or ran out of its budget (status 1)
#include <stdexcept>
#include <string>

namespace afmkit {

/// A parameter is outside its allowed range (or not finite). `parameter()` names it.
class InvalidParameter : public std::invalid_argument {
 public:
  InvalidParameter(std::string parameter, const std::string& message)
      : std::invalid_argument(message), parameter_(std::move(parameter)) {}
  const std::string& parameter() const& noexcept { return parameter_; }
  std::string parameter() const&& { return parameter_; }

 private:
  std::string parameter_;
};

/// Bad input that is not a single parameter: a missing or malformed file, an unknown key.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An iterative method did not converge, or an iteration / event / time budget was exhausted.
class NumericalFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace afmkit
