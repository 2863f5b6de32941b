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
                    "energy_dissipated", "jumped", "floquet_max", "peak_force", "min_gap", "harmonic_2", "harmonic_3",
                    "harmonic_4", "harmonic_5", "hb_amplitude", "hb_offset", "hb_phase", "hb_solutions"});
}

void add_sweep_rows(io::Table& table, const std::vector<tapping::SweepPoint>& points, const tapping::UnitScales& s) {
  for (const tapping::SweepPoint& p : points) {
    const tapping::OrbitMetrics& m = p.metrics;
    table.add_row({p.separation * s.length, std::string(tapping::direction_name(p.direction)), m.amplitude * s.length,
                   m.offset * s.length, m.phase, p.orbit.stable, m.contact_fraction, m.energy_dissipated() * s.energy,
                   p.jumped, p.orbit.floquet_max, m.peak_force * s.force, m.min_gap * s.length,
                   m.harmonics[0] * s.length, m.harmonics[1] * s.length, m.harmonics[2] * s.length,
                   m.harmonics[3] * s.length, p.hb_amplitude * s.length, p.hb_offset * s.length, p.hb_phase,
                   static_cast<long>(p.hb_solutions)});
  }
}

}  // namespace afmkit::cli
