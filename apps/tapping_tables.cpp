#include "tapping_tables.hpp"

#include <algorithm>

namespace afmkit::cli {

std::vector<io::Column> hb_columns(const tapping::UnitScales& s) {
  const std::string L = s.length_unit;
  return {{"q", "dimensionless", "penetration parameter q = (A + l)/B (seed-1 eq. 15); q >= 1: free oscillation"},
          {"separation", L, "separation l where this harmonic-balance solution exists"},
          {"amplitude", L, "first-harmonic amplitude B of x(t) = A + B cos(ωt − φ)"},
          {"offset", L, "mean deflection A"},
          {"phase", "rad", "phase lag φ of the first harmonic behind the drive (docs/conventions.md), in (-π, π]"},
          {"branch", "label", "root of the harmonic-balance quadratic: plus, minus or free "
                              "(docs/theory-tapping.md#two-branch-solution)"}};
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

std::vector<io::Column> sweep_columns(const tapping::UnitScales& s) {
  const std::string L = s.length_unit;
  return {{"separation", L, "separation l of the orbit"},
          {"direction", "label", "approach, retract (instrument sweep) or continuation"},
          {"amplitude", L, "first-harmonic amplitude B of the periodic orbit"},
          {"offset", L, "mean deflection A of the orbit"},
          {"phase", "rad", "phase lag φ of the first harmonic behind the drive (docs/conventions.md), in (-π, π]"},
          {"stable", "boolean (0/1)", "1: all Floquet multipliers inside the unit circle"},
          {"contact_fraction", "dimensionless", "fraction of the period with the gap below the law's contact gap"},
          {"energy_dissipated", s.energy_unit, "energy dissipated per drive period (viscous + contact)"},
          {"peak_force", s.force_unit, "largest tip-sample force over the period (positive: repulsive)"},
          {"min_gap", L, "smallest gap x + l over the period"},
          {"floquet_max", "dimensionless", "largest Floquet multiplier modulus"},
          {"period_multiple", "count", "n of a period-n orbit (1: the drive period)"},
          {"periodic", "boolean (0/1)", "0: the transient did not settle (metrics describe one period of it)"},
          {"jumped", "boolean (0/1)", "1: the response jumped to another branch at this point"},
          {"arclength", L, "pseudo-arclength of the continuation (state scaled by the amplitude; 0 in instrument sweeps)"},
          {"harmonic_2", L, "amplitude of the 2nd harmonic of x(t)"},
          {"harmonic_3", L, "amplitude of the 3rd harmonic of x(t)"},
          {"hb_amplitude", L, "nearest harmonic-balance amplitude at the same separation (nan: none)"},
          {"hb_offset", L, "its mean deflection (nan: none)"},
          {"hb_phase", "rad", "its phase (nan: none)"},
          {"hb_solutions", "count", "number of harmonic-balance solutions at this separation"},
          {"trapped", "boolean (0/1)", "1: the tip sticks to the sample or stays in contact over the whole period (no "
                                       "tapping; docs/conventions.md#statuses): amplitude is its motion in contact"}};
}

}  // namespace afmkit::cli
