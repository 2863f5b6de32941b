// JKR-like adhesion hysteresis (docs/force-laws.md).
#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"
#include "law_units.hpp"

namespace afmkit::impact {

AdhesionHysteresisLaw::AdhesionHysteresisLaw(double e, double r, double hamaker, double a0, double gamma,
                                             bool allow_gain)
    : modulus_(validate::positive("effective_modulus", e)),
      radius_(validate::positive("tip_radius", r)),
      hamaker_(validate::non_negative("hamaker", hamaker) * joule_per_nm_in_nN),
      a0_(validate::positive("intermolecular_distance", a0)),
      // F_pull = (3/2)πγR: γ [J/m² = N/m] · R [nm] = nN
      pull_off_(1.5 * std::numbers::pi * validate::non_negative("adhesion_energy", gamma) * r),
      allow_gain_(allow_gain) {
  validate::finite("pull_off_force", pull_off_);
}

double AdhesionHysteresisLaw::approach(double d) const {
  if (d >= a0_) return -hamaker_ * radius_ / (6.0 * d * d);
  const double delta = a0_ - d;
  return -hamaker_ * radius_ / (6.0 * a0_ * a0_) + 4.0 / 3.0 * modulus_ * std::sqrt(radius_) * delta * std::sqrt(delta);
}

double AdhesionHysteresisLaw::departure(double d) const {
  if (d >= a0_) return approach(d);
  const double delta = a0_ - d;
  return -pull_off_ + 4.0 / 3.0 * modulus_ * std::sqrt(radius_) * delta * std::sqrt(delta);
}
double AdhesionHysteresisLaw::approach_slope(double d) const {
  if (d >= a0_) return hamaker_ * radius_ / (3.0 * d * d * d);
  return -2.0 * modulus_ * std::sqrt(radius_ * (a0_ - d));
}
double AdhesionHysteresisLaw::departure_slope(double d) const { return approach_slope(d); }  // same shape, shifted

void AdhesionHysteresisLaw::require_dissipative() const {
  // H_a − H_b = F_pull − A_H R/(6 a0²) in contact (d < a0), 0 outside: ≥ 0 iff F_pull ≥ A_H R/(6 a0²)
  const double contact_attraction = hamaker_ * radius_ / (6.0 * a0_ * a0_);
  if (allow_gain_ || pull_off_ >= contact_attraction) return;
  throw InvalidParameter("adhesion_energy",
                         fmt::format("adhesion_energy gives a pull-off force (3/2)πγR = {:.6g} nN below the van der "
                                     "Waals attraction at contact A_H R/(6 a0²) = {:.6g} nN: the retract branch would "
                                     "lie above the approach branch (energy gain); raise adhesion_energy or set "
                                     "allow_energy_gain = true",
                                     pull_off_, contact_attraction));
}

// ∫_lo^hi (H_a − H_b) dd = (F_pull − A_H R/(6a0²))·(min(hi, a0) − lo)₊
double AdhesionHysteresisLaw::hysteresis_area(double lo, double hi) const {
  const double u = std::min(hi, a0_);
  if (!(lo < u)) return 0.0;
  return (pull_off_ - hamaker_ * radius_ / (6.0 * a0_ * a0_)) * (u - lo);
}

}  // namespace afmkit::impact
