#pragma once
// The CSV tables of tapping results, shared by `tapping hb`, `tapping sweep` and `demo`, so that their
// column names, units and descriptions (which users rely on) are defined once.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "afmkit/io/output.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"
#include "command.hpp"

namespace afmkit::cli {

/// Columns: q, separation, amplitude, offset, phase, branch (lengths in the units of `scales`).
std::vector<io::Column> hb_columns(const tapping::UnitScales& scales);
/// Rows of the curve into `out` (a CommandOutput or an io::TableWriter opened with hb_columns).
template <class Table>
void write_hb_rows(Table& out, std::span<const tapping::HbPoint> curve, const tapping::UnitScales& s) {
  for (const tapping::HbPoint& pt : curve)
    out.row(pt.q, pt.separation * s.length, pt.amplitude * s.length, pt.offset * s.length, pt.phase,
            tapping::branch_name(pt.branch));
}

/// The folds of harmonic balance as records (q, separation, amplitude, offset, phase, branch, kind = maximum or
/// minimum of l(q)) sorted by separation — as `tapping hb` and `demo` report them.
nlohmann::json hb_fold_records(const tapping::HarmonicBalance& hb, const tapping::UnitScales& s);

/// Columns: separation, direction, amplitude, offset, phase, stable, contact_fraction, energy_dissipated,
/// then peak_force, min_gap, floquet_max, period_multiple, periodic, jumped, arclength, harmonic_2, harmonic_3,
/// hb_amplitude, hb_offset, hb_phase, hb_solutions, trapped.
std::vector<io::Column> sweep_columns(const tapping::UnitScales& scales);
/// Direction label of a row: approach / retract in separation sweeps, down / up in sweeps of another parameter
/// (the values visited from the largest down, then back up); continuation either way.
inline const char* sweep_direction_label(tapping::SweepDirection d, bool separation) {
  if (separation || d == tapping::SweepDirection::continuation) return tapping::direction_name(d);
  return d == tapping::SweepDirection::approach ? "down" : "up";
}
/// Rows of the points into `out` (a CommandOutput or an io::TableWriter opened with sweep_columns). With
/// `parameter_factor` (a sweep in another parameter than the separation) each row starts with the point's value of
/// the swept parameter times that factor (a column the caller put first) and directions are labelled down / up.
template <class Table>
void write_sweep_rows(Table& out, const std::vector<tapping::SweepPoint>& points, const tapping::UnitScales& s,
                      std::optional<double> parameter_factor = std::nullopt) {
  for (const tapping::SweepPoint& pt : points) {
    const auto& m = pt.metrics;
    const auto row = [&](auto... lead) {
      out.row(lead..., pt.separation * s.length, sweep_direction_label(pt.direction, !parameter_factor),
              m.amplitude * s.length, m.offset * s.length, m.phase, pt.orbit.stable, m.contact_fraction,
              m.energy_dissipated() * s.energy, m.peak_force * s.force, m.min_gap * s.length, pt.orbit.floquet_max,
              pt.orbit.period_multiple, pt.periodic, pt.jumped, pt.arclength, m.harmonics[0] * s.length,
              m.harmonics[1] * s.length, pt.hb_amplitude * s.length, pt.hb_offset * s.length, pt.hb_phase,
              pt.hb_solutions, tapping::tip_trapped(m));
    };
    if (parameter_factor) row(pt.parameter * *parameter_factor);
    else row();
  }
}

}  // namespace afmkit::cli
