#include "tapping_tables.hpp"

#include <string>

namespace afmkit::cli {

io::Table hb_table(const std::vector<tapping::HbPoint>& curve, const tapping::UnitScales& s) {
  io::Table table({"q", "separation", "amplitude", "offset", "phase", "branch"});
  for (const tapping::HbPoint& pt : curve)
    table.add_row({pt.q, pt.separation * s.length, pt.amplitude * s.length, pt.offset * s.length, pt.phase,
                   std::string(tapping::branch_name(pt.branch))});
  return table;
}

io::Table sweep_table_columns() {
  return io::Table({"separation", "direction", "amplitude", "offset", "phase", "stable", "contact_fraction",
                    "energy_dissipated", "peak_force", "min_gap", "floquet_max", "period_multiple", "periodic",
                    "jumped", "arclength", "harmonic_2", "harmonic_3", "hb_amplitude", "hb_offset", "hb_phase",
                    "hb_solutions"});
}

void add_sweep_rows(io::Table& table, const std::vector<tapping::SweepPoint>& points, const tapping::UnitScales& s) {
  for (const tapping::SweepPoint& pt : points) {
    const auto& m = pt.metrics;
    table.add_row({pt.separation * s.length, std::string(tapping::direction_name(pt.direction)),
                   m.amplitude * s.length, m.offset * s.length, m.phase, pt.orbit.stable, m.contact_fraction,
                   m.energy_dissipated() * s.energy, m.peak_force * s.force, m.min_gap * s.length,
                   pt.orbit.floquet_max, static_cast<long>(pt.orbit.period_multiple), pt.periodic, pt.jumped,
                   pt.arclength, m.harmonics[0] * s.length, m.harmonics[1] * s.length, pt.hb_amplitude * s.length,
                   pt.hb_offset * s.length, pt.hb_phase, static_cast<long>(pt.hb_solutions)});
  }
}

}  // namespace afmkit::cli
