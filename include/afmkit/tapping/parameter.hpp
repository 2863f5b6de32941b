#pragma once
// The parameter a sweep or a continuation moves (docs/theory-tapping.md#parameter-continuation). The system is
// the same whatever the parameter; only which model each value gives changes: the separation l (the default),
// the drive frequency ω or amplitude Γ, or any numeric parameter of the force law (a model built by the caller
// for each value, e.g. from the law registry).
#include <functional>
#include <string>

#include "afmkit/tapping/model.hpp"

namespace afmkit::tapping {

class SweepParameter {
 public:
  /// The model at a value of the parameter (thread-safe; InvalidParameter for a value the model refuses).
  using ModelAt = std::function<TappingModel(const TappingModel& base, double value)>;

  /// The separation l: the continuation uses the exact ∂P/∂l of the variational equations.
  static SweepParameter separation();
  /// The drive frequency ω (rad per model time unit; the drive amplitude Γ held).
  static SweepParameter drive_frequency();
  /// The drive amplitude Γ (force per unit mass; ω held).
  static SweepParameter drive_amplitude();
  /// Any other parameter, named `name`: `model_at(base, value)` gives the model. Its ∂P/∂p is taken by central
  /// differences of the stroboscopic map (the orbits themselves are exact: only the continuation's tangent uses it).
  SweepParameter(std::string name, ModelAt model_at);

  const std::string& name() const& { return name_; }
  bool is_separation() const { return separation_; }
  /// The model at `value` of the parameter, the rest as in `base`.
  TappingModel at(const TappingModel& base, double value) const;

 private:
  std::string name_;
  ModelAt model_at_;
  bool separation_ = false;
};

}  // namespace afmkit::tapping
