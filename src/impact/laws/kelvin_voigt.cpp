// Kelvin–Voigt viscoelastic DMT contact (docs/force-laws.md).
#include <cmath>

#include "afmkit/core/validate.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"

namespace afmkit::impact {

KelvinVoigtLaw::KelvinVoigtLaw(double e, double r, double hamaker, double a0, double viscosity)
    : modulus_(validate::positive("effective_modulus", e)),
      radius_(validate::positive("tip_radius", r)),
      hamaker_(validate::non_negative("hamaker", hamaker) * 1e18),  // J/nm -> nN
      a0_(validate::positive("intermolecular_distance", a0)),
      viscosity_(validate::non_negative("viscosity", viscosity)) {}

double KelvinVoigtLaw::approach(double d) const {
  if (d >= a0_) return -hamaker_ * radius_ / (6.0 * d * d);
  const double delta = a0_ - d;
  return -hamaker_ * radius_ / (6.0 * a0_ * a0_) + 4.0 / 3.0 * modulus_ * std::sqrt(radius_) * delta * std::sqrt(delta);
}

// c(d) = η √(R δ): Pa·s · nm = 1e-9 nN·s/nm
double KelvinVoigtLaw::damping(double d) const {
  if (d >= a0_) return 0.0;
  return 1e-9 * viscosity_ * std::sqrt(radius_ * (a0_ - d));
}

}  // namespace afmkit::impact
