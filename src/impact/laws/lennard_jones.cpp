// Lennard-Jones sphere–plane interaction (docs/force-laws.md).
#include <algorithm>
#include <cmath>

#include "afmkit/core/validate.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"

namespace afmkit::impact {

LennardJonesLaw::LennardJonesLaw(double r, double hamaker, double a0)
    : coefficient_(validate::positive("tip_radius", r) * validate::positive("hamaker", hamaker) * 1e18 / 6.0),
      a0_(validate::positive("intermolecular_distance", a0)) {
  validate::finite("hamaker", coefficient_);
}

double LennardJonesLaw::force_at(double d) const {
  const double r2 = a0_ * a0_ / (d * d), r6 = r2 * r2 * r2;
  return coefficient_ / (d * d) * (r6 - 1.0);  // (A_H R/6)(−1/d² + a0⁶/d⁸)
}

double LennardJonesLaw::approach_slope(double d) const {
  const double x = std::max(d, 0.5 * a0_);  // the tangent below a0/2 has the slope at a0/2
  const double r2 = a0_ * a0_ / (x * x), r6 = r2 * r2 * r2;
  return coefficient_ / (x * x * x) * (2.0 - 8.0 * r6);
}

double LennardJonesLaw::approach(double d) const {
  const double d_min = 0.5 * a0_;
  if (d >= d_min) return force_at(d);
  // tangent at a0/2: dH/dd = (A_H R/6)(2/d³ − 8 a0⁶/d⁹)
  const double r2 = a0_ * a0_ / (d_min * d_min), r6 = r2 * r2 * r2;
  const double slope = coefficient_ / (d_min * d_min * d_min) * (2.0 - 8.0 * r6);
  return force_at(d_min) + slope * (d - d_min);
}

}  // namespace afmkit::impact
