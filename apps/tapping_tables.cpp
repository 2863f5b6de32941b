#include "tapping_tables.hpp"

#include <algorithm>

namespace afmkit::cli {

io::TableOf<tapping::HbPoint> hb_table(const TappingUnits& u) {
  using P = tapping::HbPoint;
  return {{"q", "dimensionless", "penetration parameter q = (A + l)/B (seed-1 eq. 15); q >= 1: free oscillation", &P::q},
          {"separation", u.length, "separation l where this harmonic-balance solution exists", &P::separation},
          {"amplitude", u.length, "first-harmonic amplitude B of x(t) = A + B cos(ωt − φ)", &P::amplitude},
          {"offset", u.length, "mean deflection A", &P::offset},
          {"phase", "rad", "phase lag φ of the first harmonic behind the drive (docs/conventions.md), in (-π, π]",
           &P::phase},
          {"branch", "label",
           "root of the harmonic-balance quadratic: plus, minus or free (docs/theory-tapping.md#two-branch-solution)",
           [](const P& p) { return tapping::branch_name(p.branch); }}};
}

UnitTagged hb_point_record(const tapping::HbPoint& p, const TappingUnits& u) {
  UnitTagged j;
  j.add("q", p.q, "dimensionless")
      .add("separation", p.separation, u.length)
      .add("amplitude", p.amplitude, u.length)
      .add("offset", p.offset, u.length)
      .add("phase", p.phase, "rad")
      .add("branch", tapping::branch_name(p.branch), "label");
  return j;
}

UnitTagged hb_fold_record(const tapping::HbFold& f, const TappingUnits& u) {
  UnitTagged j = hb_point_record(f.point, u);
  j.add("kind", f.separation_maximum ? "maximum" : "minimum", "label");
  return j;
}

std::vector<UnitTagged> hb_fold_records(const tapping::HarmonicBalance& hb, const TappingUnits& u) {
  std::vector<tapping::HbFold> sorted = hb.folds();
  std::stable_sort(sorted.begin(), sorted.end(), [](const tapping::HbFold& a, const tapping::HbFold& b) {
    return a.point.separation < b.point.separation;
  });
  std::vector<UnitTagged> out;
  for (const tapping::HbFold& f : sorted) out.push_back(hb_fold_record(f, u));
  return out;
}

io::TableOf<tapping::SweepPoint> sweep_table(const TappingUnits& u, bool separation_sweep) {
  using P = tapping::SweepPoint;
  const units::Unit& L = u.length;
  return {{"separation", L, "separation l of the orbit", &P::separation},
          {"direction", "label", "approach, retract (instrument sweep) or continuation",
           [separation_sweep](const P& p) { return sweep_direction_label(p.direction, separation_sweep); }},
          {"amplitude", L, "first-harmonic amplitude B of the periodic orbit",
           [](const P& p) { return p.metrics.amplitude; }},
          {"offset", L, "mean deflection A of the orbit", [](const P& p) { return p.metrics.offset; }},
          {"phase", "rad", "phase lag φ of the first harmonic behind the drive (docs/conventions.md), in (-π, π]",
           [](const P& p) { return p.metrics.phase; }},
          {"stable", "boolean (0/1)", "1: all Floquet multipliers inside the unit circle",
           [](const P& p) { return p.orbit.stable; }},
          {"contact_fraction", "dimensionless", "fraction of the period with the gap below the law's contact gap",
           [](const P& p) { return p.metrics.contact_fraction; }},
          {"energy_dissipated", u.energy, "energy dissipated per drive period (viscous + contact)",
           [](const P& p) { return p.metrics.energy_dissipated(); }},
          {"peak_force", u.force, "largest tip-sample force over the period (positive: repulsive)",
           [](const P& p) { return p.metrics.peak_force; }},
          {"min_gap", L, "smallest gap x + l over the period", [](const P& p) { return p.metrics.min_gap; }},
          {"floquet_max", "dimensionless", "largest Floquet multiplier modulus",
           [](const P& p) { return p.orbit.floquet_max; }},
          {"period_multiple", "count", "n of a period-n orbit (1: the drive period)",
           [](const P& p) { return p.orbit.period_multiple; }},
          {"periodic", "boolean (0/1)", "0: the transient did not settle (metrics describe one period of it)",
           &P::periodic},
          {"jumped", "boolean (0/1)", "1: the response jumped to another branch at this point", &P::jumped},
          {"arclength", L,
           "pseudo-arclength of the continuation: length of the branch so far in (x(0), ẋ(0)/ω, s·p), a length "
           "(s·p = l in separation sweeps; 0 in instrument sweeps)",
           &P::arclength},
          {"harmonic_2", L, "amplitude of the 2nd harmonic of x(t)",
           [](const P& p) { return p.metrics.harmonics[0]; }},
          {"harmonic_3", L, "amplitude of the 3rd harmonic of x(t)",
           [](const P& p) { return p.metrics.harmonics[1]; }},
          {"hb_amplitude", L, "nearest harmonic-balance amplitude at the same separation (nan: none)",
           &P::hb_amplitude},
          {"hb_offset", L, "its mean deflection (nan: none)", &P::hb_offset},
          {"hb_phase", "rad", "its phase (nan: none)", &P::hb_phase},
          {"hb_solutions", "count", "number of harmonic-balance solutions at this separation", &P::hb_solutions},
          {"trapped", "boolean (0/1)",
           "1: the tip sticks to the sample or stays in contact over the whole period (no tapping; "
           "docs/conventions.md#statuses): amplitude is its motion in contact",
           [](const P& p) { return tapping::tip_trapped(p.metrics); }}};
}

}  // namespace afmkit::cli
