#pragma once
// The CSV tables of tapping results, shared by `tapping hb`, `tapping sweep` and `demo`, so that their
// column names, units and descriptions (which users rely on) are defined once.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "afmkit/io/output.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"
#include "command.hpp"
#include "tapping_params.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

/// The harmonic-balance curve's table: q, separation, amplitude, offset, phase, branch (lengths in the units of
/// `scales`), one row per HbPoint.
io::TableOf<tapping::HbPoint> hb_table(const TappingUnits& units);

/// One harmonic-balance solution as a record (q, separation, amplitude, offset, phase, branch) with its units.
UnitTagged hb_point_record(const tapping::HbPoint& point, const TappingUnits& units);
/// A fold as a record: the solution there and its kind (maximum or minimum of l(q)).
UnitTagged hb_fold_record(const tapping::HbFold& fold, const TappingUnits& units);
/// The folds of harmonic balance as records (hb_fold_record) sorted by separation — as `tapping hb` and `demo`
/// report them.
std::vector<UnitTagged> hb_fold_records(const tapping::HarmonicBalance& hb, const TappingUnits& units);

/// Direction label of a row: approach / retract in separation sweeps, down / up in sweeps of another parameter
/// (the values visited from the largest down, then back up); continuation either way.
inline const char* sweep_direction_label(tapping::SweepDirection d, bool separation) {
  if (separation || d == tapping::SweepDirection::continuation) return tapping::direction_name(d);
  return d == tapping::SweepDirection::approach ? "down" : "up";
}
/// The sweep's table, one row per SweepPoint: separation, direction, amplitude, offset, phase, stable,
/// contact_fraction, energy_dissipated, peak_force, min_gap, floquet_max, period_multiple, periodic, jumped,
/// arclength, harmonic_2, harmonic_3, hb_amplitude, hb_offset, hb_phase, hb_solutions, trapped. `separation_sweep`
/// false (a sweep in another parameter): directions are labelled down / up (the caller puts the swept parameter's
/// column first).
io::TableOf<tapping::SweepPoint> sweep_table(const TappingUnits& units, bool separation_sweep = true);

}  // namespace afmkit::cli
