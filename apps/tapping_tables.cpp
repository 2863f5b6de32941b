#include "tapping_tables.hpp"

#include <algorithm>

namespace afmkit::cli {

io::TableOf<tapping::HbPoint> hb_table(const tapping::UnitScales& s) {
  using P = tapping::HbPoint;
  const std::string L = s.length_unit;
  const double l = s.length;
  return {{"q", "dimensionless", "penetration parameter q = (A + l)/B (seed-1 eq. 15); q >= 1: free oscillation", &P::q},
          {"separation", L, "separation l where this harmonic-balance solution exists",
           [l](const P& p) { return p.separation * l; }},
          {"amplitude", L, "first-harmonic amplitude B of x(t) = A + B cos(ωt − φ)",
           [l](const P& p) { return p.amplitude * l; }},
          {"offset", L, "mean deflection A", [l](const P& p) { return p.offset * l; }},
          {"phase", "rad", "phase lag φ of the first harmonic behind the drive (docs/conventions.md), in (-π, π]",
           &P::phase},
          {"branch", "label",
           "root of the harmonic-balance quadratic: plus, minus or free (docs/theory-tapping.md#two-branch-solution)",
           [](const P& p) { return tapping::branch_name(p.branch); }}};
}

nlohmann::json hb_fold_records(const tapping::HarmonicBalance& hb, const tapping::UnitScales& s) {
  std::vector<tapping::HbFold> sorted = hb.folds();
  std::stable_sort(sorted.begin(), sorted.end(), [](const tapping::HbFold& a, const tapping::HbFold& b) {
    return a.point.separation < b.point.separation;
  });
  nlohmann::json out = nlohmann::json::array();
  for (const tapping::HbFold& f : sorted)
    out.push_back({{"q", f.point.q},
                   {"separation", f.point.separation * s.length},
                   {"amplitude", f.point.amplitude * s.length},
                   {"offset", f.point.offset * s.length},
                   {"phase", f.point.phase},
                   {"branch", tapping::branch_name(f.point.branch)},
                   {"kind", f.separation_maximum ? "maximum" : "minimum"}});
  return out;
}

io::TableOf<tapping::SweepPoint> sweep_table(const tapping::UnitScales& s, bool separation_sweep) {
  using P = tapping::SweepPoint;
  const std::string L = s.length_unit;
  const double l = s.length, energy = s.energy, force = s.force;
  return {{"separation", L, "separation l of the orbit", [l](const P& p) { return p.separation * l; }},
          {"direction", "label", "approach, retract (instrument sweep) or continuation",
           [separation_sweep](const P& p) { return sweep_direction_label(p.direction, separation_sweep); }},
          {"amplitude", L, "first-harmonic amplitude B of the periodic orbit",
           [l](const P& p) { return p.metrics.amplitude * l; }},
          {"offset", L, "mean deflection A of the orbit", [l](const P& p) { return p.metrics.offset * l; }},
          {"phase", "rad", "phase lag φ of the first harmonic behind the drive (docs/conventions.md), in (-π, π]",
           [](const P& p) { return p.metrics.phase; }},
          {"stable", "boolean (0/1)", "1: all Floquet multipliers inside the unit circle",
           [](const P& p) { return p.orbit.stable; }},
          {"contact_fraction", "dimensionless", "fraction of the period with the gap below the law's contact gap",
           [](const P& p) { return p.metrics.contact_fraction; }},
          {"energy_dissipated", s.energy_unit, "energy dissipated per drive period (viscous + contact)",
           [energy](const P& p) { return p.metrics.energy_dissipated() * energy; }},
          {"peak_force", s.force_unit, "largest tip-sample force over the period (positive: repulsive)",
           [force](const P& p) { return p.metrics.peak_force * force; }},
          {"min_gap", L, "smallest gap x + l over the period", [l](const P& p) { return p.metrics.min_gap * l; }},
          {"floquet_max", "dimensionless", "largest Floquet multiplier modulus",
           [](const P& p) { return p.orbit.floquet_max; }},
          {"period_multiple", "count", "n of a period-n orbit (1: the drive period)",
           [](const P& p) { return p.orbit.period_multiple; }},
          {"periodic", "boolean (0/1)", "0: the transient did not settle (metrics describe one period of it)",
           &P::periodic},
          {"jumped", "boolean (0/1)", "1: the response jumped to another branch at this point", &P::jumped},
          {"arclength", L, "pseudo-arclength of the continuation (state scaled by the amplitude; 0 in instrument sweeps)",
           &P::arclength},
          {"harmonic_2", L, "amplitude of the 2nd harmonic of x(t)",
           [l](const P& p) { return p.metrics.harmonics[0] * l; }},
          {"harmonic_3", L, "amplitude of the 3rd harmonic of x(t)",
           [l](const P& p) { return p.metrics.harmonics[1] * l; }},
          {"hb_amplitude", L, "nearest harmonic-balance amplitude at the same separation (nan: none)",
           [l](const P& p) { return p.hb_amplitude * l; }},
          {"hb_offset", L, "its mean deflection (nan: none)", [l](const P& p) { return p.hb_offset * l; }},
          {"hb_phase", "rad", "its phase (nan: none)", &P::hb_phase},
          {"hb_solutions", "count", "number of harmonic-balance solutions at this separation", &P::hb_solutions},
          {"trapped", "boolean (0/1)",
           "1: the tip sticks to the sample or stays in contact over the whole period (no tapping; "
           "docs/conventions.md#statuses): amplitude is its motion in contact",
           [](const P& p) { return tapping::tip_trapped(p.metrics); }}};
}

}  // namespace afmkit::cli
