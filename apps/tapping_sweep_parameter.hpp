#pragma once
// The parameter `afmkit tapping sweep` moves (--parameter): the separation (the default), the drive frequency
// (ω/ω_n with the drive force held), or any numeric model or law key of the run (drive_amplitude, free_amplitude,
// quality_factor, approach_stiffness, effective_modulus, …) in that key's own units, the rest of the run as given
// (docs/commands.md#tapping-sweep, docs/theory-tapping.md#parameter-continuation).
#include <memory>
#include <string>
#include <vector>

#include "afmkit/io/params.hpp"
#include "afmkit/tapping/parameter.hpp"

namespace afmkit::cli {

/// Every name --parameter accepts for some run (its choices): separation, drive_frequency and the numeric keys of
/// add_tapping_model_params.
std::vector<std::string> sweep_parameter_names();

/// The swept parameter of a run and its range in the user's units.
struct SweptParameter {
  tapping::SweepParameter parameter;  // takes values in the user's units of `name`
  std::string name;
  std::string unit;
  double min = 0.0, max = 0.0;
};

/// The parameter named by `parameter` with the range parameter_min, parameter_max (not the separation: the caller
/// handles it). InvalidParameter (exit 2): a name that is not a parameter of this run (naming `parameter`), a range
/// missing, reversed or outside the parameter's allowed range (naming parameter_min or parameter_max and the key).
SweptParameter swept_parameter_from(const io::ParamSet& p,
                                    std::shared_ptr<const impact::ForceLawModel> law_object = nullptr);

}  // namespace afmkit::cli
