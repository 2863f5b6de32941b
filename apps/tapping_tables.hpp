#pragma once
// The CSV tables of tapping results, shared by `tapping hb`, `tapping sweep` and `demo`, so that their
// column names (which users rely on) are defined once.
#include <string>
#include <vector>

#include "afmkit/io/output.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::cli {

/// Columns: q, separation, amplitude, offset, phase, branch.
std::vector<std::string> hb_columns();
void write_hb_rows(io::TableWriter& out, const std::vector<tapping::HbPoint>& curve, const tapping::UnitScales& scales);

/// Columns: separation, direction, amplitude, offset, phase, stable, contact_fraction, energy_dissipated,
/// then peak_force, min_gap, floquet_max, period_multiple, periodic, jumped, arclength, harmonic_2, harmonic_3,
/// hb_amplitude, hb_offset, hb_phase, hb_solutions.
std::vector<std::string> sweep_columns();
void write_sweep_rows(io::TableWriter& out, const std::vector<tapping::SweepPoint>& points,
                      const tapping::UnitScales& scales);

}  // namespace afmkit::cli
