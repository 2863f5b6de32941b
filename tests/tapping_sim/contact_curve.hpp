#pragma once
// A realistic measured-like force curve for the contact-aware hysteresis tests (docs/force-laws.md#hysteresis):
// approach = DMT + van der Waals (E* = 1 GPa, R = 10 nm, A_H = 6.4e-20 J, a0 = 0.165 nm); retract = DMT with
// E* = 0.8 GPa minus an adhesion neck of 3 nN that thins out and breaks at the pull-off distance +14 nm:
// neck(d) = 3 nN (1 − (d − a0)/(14 nm − a0))⁴ for a0 < d < 14 nm, 3 nN below a0, 0 above (the 4th power ends it
// smoothly enough that the PCHIP retract never rises above the approach where the neck ends: a dissipative law).
// Sampled every 0.1 nm from −2 nm to 40 nm (3-column table, as AFM software exports it).
#include <algorithm>
#include <cmath>

#include "afmkit/impact/laws/table_law.hpp"

namespace afmkit_test {

inline constexpr double kNeckA0 = 0.165;      // nm
inline constexpr double kPullOff = 14.0;      // nm
inline constexpr double kNeckForce = 3.0;     // nN

inline double dmt_force(double d, double modulus_gpa) {
  const double r = 10.0, hamaker = 6.4e-20;
  // A_H [J] = 1e18 A_H aJ = 1e18 A_H nN·nm, so A_H R/(6 d²) with R, d in nm is in nN
  const double ahr = hamaker * 1e18 * r;
  if (d >= kNeckA0) return -ahr / (6.0 * d * d);
  // (4/3) E* √R δ^{3/2}: E* [GPa] = 1 nN/nm²
  return -ahr / (6.0 * kNeckA0 * kNeckA0) + 4.0 / 3.0 * modulus_gpa * std::sqrt(r) * std::pow(kNeckA0 - d, 1.5);
}

inline double neck_force(double d) {
  if (d >= kPullOff) return 0.0;
  if (d <= kNeckA0) return kNeckForce;
  const double u = 1.0 - (d - kNeckA0) / (kPullOff - kNeckA0);
  return kNeckForce * (u * u) * (u * u);
}

/// `drag` [nN]: a constant difference of the branches over the whole table (hydrodynamic drag, or a baseline
/// offset left between approach and retract), as measured curves have; `top` [nm]: the table's last distance.
inline afmkit::impact::ForceCurve neck_curve(double drag = 0.0, double top = 40.0) {
  afmkit::impact::ForceCurve c;
  c.origin = "neck curve";
  const int n = static_cast<int>(std::lround((top + 2.0) / 0.1));
  for (int i = 0; i <= n; ++i) {
    const double d = -2.0 + 0.1 * i;
    c.approach_gap.push_back(d);
    c.approach_force.push_back(dmt_force(d, 1.0));
    c.retract_gap.push_back(d);
    c.retract_force.push_back(dmt_force(d, 0.8) - neck_force(d) - drag);
  }
  return c;
}

/// The same curve with the retract branch replaced by the approach branch (a conservative law).
inline afmkit::impact::ForceCurve approach_only_curve(double top = 40.0) {
  auto c = neck_curve(0.0, top);
  c.retract_force = c.approach_force;
  return c;
}

}  // namespace afmkit_test
