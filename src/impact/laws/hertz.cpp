// Hertz contact (docs/force-laws.md).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"

namespace afmkit::impact {

HertzLaw::HertzLaw(double ea, double eb, double r, bool allow_gain)
    : modulus_a_(validate::positive("effective_modulus", ea)),
      modulus_b_(validate::positive("departure_modulus", eb)),
      radius_(validate::positive("tip_radius", r)),
      allow_gain_(allow_gain) {}

double HertzLaw::approach(double d) const {
  if (d >= 0) return 0.0;
  return 4.0 / 3.0 * modulus_a_ * std::sqrt(radius_) * (-d) * std::sqrt(-d);
}
double HertzLaw::departure(double d) const {
  if (d >= 0) return 0.0;
  return 4.0 / 3.0 * modulus_b_ * std::sqrt(radius_) * (-d) * std::sqrt(-d);
}
double HertzLaw::approach_slope(double d) const { return d >= 0 ? 0.0 : -2.0 * modulus_a_ * std::sqrt(-radius_ * d); }
double HertzLaw::departure_slope(double d) const { return d >= 0 ? 0.0 : -2.0 * modulus_b_ * std::sqrt(-radius_ * d); }

void HertzLaw::require_dissipative() const {
  if (allow_gain_ || modulus_b_ <= modulus_a_) return;
  throw InvalidParameter("departure_modulus",
                         fmt::format("departure_modulus = {} must be <= effective_modulus = {} (a hysteresis law "
                                     "dissipates energy; set allow_energy_gain = true to allow a gain)",
                                     modulus_b_, modulus_a_));
}

// ∫_lo^hi (H_a − H_b) dd = (8/15)(E*_a − E*_b)√R ((−lo)^{5/2} − (−u)^{5/2}), u = min(hi, 0)
double HertzLaw::hysteresis_area(double lo, double hi) const {
  const double u = std::min(hi, 0.0);
  if (!(lo < u)) return 0.0;
  const double p = -lo, q = -u;
  return 8.0 / 15.0 * (modulus_a_ - modulus_b_) * std::sqrt(radius_) * (p * p * std::sqrt(p) - q * q * std::sqrt(q));
}

}  // namespace afmkit::impact
