#pragma once
// Model parameters shared by `afmkit tapping orbit | hb | sweep` (and the demo), in normalised or physical
// units (docs/units.md). Keys of the other unit system are rejected when given explicitly.
#include <memory>
#include <string>
#include <vector>

#include "afmkit/core/units.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/tapping/model.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::cli {

/// Unit of a length parameter of the tapping commands: nm in physical runs, the model length L in normalised runs.
inline constexpr const char* kLengthUnit = "nm (physical) or L (normalised)";
/// The keys of the uniform grid of separations, which an explicit list (separations, separations_file) replaces:
/// a run given a list records the list, not the grid it did not use.
inline std::vector<std::string> uniform_grid_keys() { return {"separation_min", "separation_max", "points"}; }

/// `separations` (an explicit list, described by `help`) and `separations_file`, either replacing the uniform grid
/// (uniform_grid_keys) in the records; shared by tapping sweep and tapping fm.
void add_separation_list_params(io::ParamSet& p, const std::string& help);

/// What a command that visits a range of separations says of it, where it differs from the others: the demo's
/// defaults are its demonstration case, scaled in physical units to the cantilever (any finite value).
struct SeparationRangeForm {
  std::string min_help = "smallest separation (rest position to the surface) of the range visited";
  std::string max_help = "largest separation of the range visited, where an approach starts (not below "
                         "separation_min)";
  io::Range range = io::Range::closed(-1e6, 1e6);  // like every separation
  std::string min_default_text, max_default_text;  // empty: the defaults' values
};
/// separation_min and separation_max of the commands that visit a range of separations (tapping sweep, grid, fm,
/// modes, demo), each with its defaults (each command checks their order).
void add_separation_range_params(io::ParamSet& p, double min_default, double max_default,
                                 const SeparationRangeForm& form = {});
/// `points`: the number of separations on [separation_min, separation_max] of the same commands, each with its
/// default, bounds (its cost per point) and help.
void add_separation_points_param(io::ParamSet& p, long points_default, long min_points, long max_points,
                                 const std::string& help);

/// units, cantilever, drive, force law, separation.
void add_tapping_model_params(io::ParamSet& p);
/// The normalised model at the parameter `separation` (nm in physical units). `law_object`: the caller's law of
/// law = python (law_object_of(capture); null on the command line).
tapping::TappingModel tapping_model_from(const io::ParamSet& p,
                                         std::shared_ptr<const impact::ForceLawModel> law_object = nullptr);
using TappingScales = tapping::UnitScales;
/// Factors converting model quantities to the user's units (all 1 for normalised units).
TappingScales tapping_scales_from(const io::ParamSet& p);

/// The units of the tapping commands' results, each converting a model quantity into the user's unit and naming it
/// (nm, nN, aJ, s in physical runs; L, L/t^2, L^2/t^2, t in normalised ones): the one edge from the model's
/// normalised units to the user's (afmkit/core/units.hpp, docs/units.md).
struct TappingUnits {
  units::Unit length, force, energy, time, velocity;
  explicit TappingUnits(const TappingScales& s)
      : length{s.length_unit, s.length},
        force{s.force_unit, s.force},
        energy{s.energy_unit, s.energy},
        time{s.time_unit, s.time},
        velocity(length.per(time)) {}

  /// The same names and factors (a table declared for one is the other's: TableCache).
  friend bool operator==(const TappingUnits&, const TappingUnits&) = default;
};

}  // namespace afmkit::cli
