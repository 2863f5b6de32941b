#pragma once
// A force law written in Python as a ForceLawModel (python_law.cpp explains the tabulation and its cost).
// Units inside: gap nm, force nN, damping nN·s/nm (= N·s/m), as the built-in physical laws (docs/force-laws.md).
#include <atomic>
#include <cstddef>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "afmkit/impact/force_law.hpp"

namespace afmkit::python {

/// A law's callable failed during a run (raised, or returned anything but one finite number): the user's error.
/// Not an InvalidParameter, which a computation turns into a NumericalFailure of its own (core/computed.hpp): the
/// Python module reports it as afmkit.InvalidParameter naming `law` once the run has stopped.
class PythonLawError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The tabulation of one branch (python/afmkit/_python_law.py): piece i covers gaps [edges[i], edges[i+1]) [nm]
/// and is a Chebyshev series of degree `degree` in u ∈ [u_low[i], u_high[i]], where d = u (signs[i] = 0) or
/// d = anchors[i] + signs[i]·u² (next to a switching gap: u = √|d − g|); coefficients NaN: evaluated by the
/// callable. `slopes`: the series of dF/du.
struct BranchTable {
  std::vector<double> edges, coefficients, slopes, u_low, u_high, signs, anchors;
  int degree = 0;
};

/// One branch (H_a, H_b or c) of a Python law: its table inside the domain, the callable beyond. `factor` converts
/// the callable's SI value to the law's units (1e9 for N -> nN; 1 for N·s/m -> nN·s/nm).
class PythonBranch {
 public:
  PythonBranch(std::string label, pybind11::object callable, double factor, BranchTable table);
  ~PythonBranch();
  PythonBranch(const PythonBranch&) = delete;
  PythonBranch& operator=(const PythonBranch&) = delete;

  double value(double gap) const;  ///< at gap [nm], in the law's units
  double slope(double gap) const;  ///< d value / d gap
  /// The callable itself at one gap (takes the GIL); PythonLawError naming the callable when it raises or returns
  /// anything but one finite number.
  double call(double gap) const;

 private:
  std::string label_;  // "approach=<function f>": how messages name the callable
  std::shared_ptr<pybind11::object> callable_;
  double factor_;
  BranchTable t_;
  /// The piece of the last evaluation: the integrators ask for nearby gaps in turn, so it is tried first (shared by
  /// the threads of a run: any value is a valid guess).
  mutable std::atomic<std::size_t> hint_{0};
  /// The piece holding `gap` and its variable t ∈ [-1, 1] (and u), or -1 outside the table.
  std::ptrdiff_t locate(double gap, double& t, double& u) const;
};

class PythonLawModel final : public impact::ForceLawModel {
 public:
  /// `departure` null: the approach branch (a conservative law); `damping` null: no Kelvin–Voigt term.
  /// `contact_gap` NaN: the lowest switching gap (ForceLawModel's default).
  PythonLawModel(std::string name, std::shared_ptr<const PythonBranch> approach,
                 std::shared_ptr<const PythonBranch> departure, std::shared_ptr<const PythonBranch> damping,
                 std::vector<double> switching_gaps, double contact_gap);
  std::string name() const override { return name_; }
  double approach(double gap) const override { return approach_->value(gap); }
  double departure(double gap) const override { return departure_->value(gap); }
  bool has_slopes() const override { return true; }
  double approach_slope(double gap) const override { return approach_->slope(gap); }
  double departure_slope(double gap) const override { return departure_->slope(gap); }
  double damping(double gap) const override { return damping_ ? damping_->value(gap) : 0.0; }
  bool has_damping() const override { return damping_ != nullptr; }
  std::vector<double> switching_gaps() const override { return switching_gaps_; }
  double contact_gap() const override;
  bool branch_dependent(int) const override { return !conservative_; }
  double hysteresis_area(double, double) const override {
    return conservative_ ? 0.0 : std::numeric_limits<double>::quiet_NaN();
  }

 private:
  std::string name_;
  std::shared_ptr<const PythonBranch> approach_, departure_, damping_;
  std::vector<double> switching_gaps_;
  double contact_gap_;
  bool conservative_;
};

}  // namespace afmkit::python
