#pragma once
// Parameters of `afmkit tapping fm` beyond the shared tapping model and numerics (tapping_params.hpp,
// tapping_sim_params.hpp): the amplitude setpoint, the separations, the continuation's bisections.
#include <vector>

#include "afmkit/core/units.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/tapping/fm.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::cli {

/// The "FM-AFM" group: amplitude, separation_min, separation_max, points, separations, separations_file,
/// max_bisections.
void add_tapping_fm_params(io::ParamSet& p);
/// Refuses (InvalidParameter, naming the key) the shared keys that set the drive or search periodic orbits of a
/// driven cantilever, which do not apply to the self-excited one: drive_amplitude, free_amplitude,
/// frequency_ratio, separation, max_period_multiple, max_transient_periods.
void reject_keys_not_for_fm(const io::ParamSet& p);
/// The separations (model units), in decreasing order (an approach): the explicit list when one is given, else
/// `points` equally spaced in [separation_min, separation_max].
std::vector<double> fm_separations(const io::ParamSet& p, const units::Unit& length);
/// The amplitude setpoint A in model units.
double fm_amplitude(const io::ParamSet& p, const units::Unit& length);

}  // namespace afmkit::cli
