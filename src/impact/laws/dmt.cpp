// DMT contact with van der Waals attraction (see force_law.hpp and docs/force-laws.md).
#include <algorithm>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/impact/force_law.hpp"
#include "law_units.hpp"

namespace afmkit::impact {

DmtLaw::DmtLaw(double ea, double eb, double r, double ha, double hb, double a0, bool allow_gain)
    : effective_modulus_approach(validate::positive("effective_modulus_approach", ea)),
      effective_modulus_departure(validate::positive("effective_modulus_departure", eb)),
      tip_radius(validate::positive("tip_radius", r)),
      hamaker_approach(validate::non_negative("hamaker_approach", ha)),
      hamaker_departure(validate::non_negative("hamaker_departure", hb)),
      intermolecular_distance(validate::positive("intermolecular_distance", a0)),
      allow_energy_gain(allow_gain) {}

void DmtLaw::require_dissipative() const {
  // H_a − H_b = (A_H,b − A_H,a) R/(6 max(d, a0)²) + (4/3)(E*_a − E*_b) √R (a0 − d)₊^{3/2} ≥ 0 for all d
  // iff E*_b ≤ E*_a and A_H,b ≥ A_H,a (seed-1 eq. 6: the loss is the area between the branches).
  if (allow_energy_gain) return;
  if (effective_modulus_departure > effective_modulus_approach)
    throw InvalidParameter("departure_modulus",
                           fmt::format("departure_modulus = {} must be <= effective_modulus = {} (a hysteresis law "
                                       "dissipates energy; set allow_energy_gain = true to allow a gain)",
                                       effective_modulus_departure, effective_modulus_approach));
  if (hamaker_departure < hamaker_approach)
    throw InvalidParameter("departure_hamaker",
                           fmt::format("departure_hamaker = {} must be >= hamaker = {} (a hysteresis law "
                                       "dissipates energy; set allow_energy_gain = true to allow a gain)",
                                       hamaker_departure, hamaker_approach));
}

namespace {

// force in nN for gap d [nm], modulus [GPa], radius [nm], Hamaker [J]
double dmt(double d, double modulus, double radius, double hamaker, double a0) {
  if (d >= a0) return -hamaker * joule_per_nm_in_nN * radius / (6.0 * d * d);
  const double delta = a0 - d;
  return -hamaker * joule_per_nm_in_nN * radius / (6.0 * a0 * a0) +
         4.0 / 3.0 * modulus * std::sqrt(radius) * delta * std::sqrt(delta);
}

/// The same for DMT (docs/units.md), in nN·nm, times `scale`: with ΔA = A_H,b − A_H,a, ΔE = E*_a − E*_b,
///   ξ ≥ a0: H_a − H_b = ΔA R/(6ξ²)                    -> ΔA R/6 · (hi − l)/(l hi), l = max(lo, a0)
///   ξ < a0: H_a − H_b = ΔA R/(6a0²) + (4/3) ΔE √R (a0 − ξ)^{3/2}
///                                                      -> ΔA R/(6a0²)(u − lo) + (8/15) ΔE √R ((a0−lo)^{5/2} − (a0−u)^{5/2})
///           with u = min(hi, a0).
double dmt_area(const DmtLaw& m, double lo, double hi) {
  const double a0 = m.intermolecular_distance, r = m.tip_radius;
  const double da = (m.hamaker_departure - m.hamaker_approach) * joule_per_nm_in_nN;
  const double de = m.effective_modulus_approach - m.effective_modulus_departure;
  double area = 0.0;
  if (hi > a0) {
    const double l = std::max(lo, a0);
    area += da * r / 6.0 * ((hi - l) / (l * hi));
  }
  if (lo < a0) {
    const double u = std::min(hi, a0);
    const double p = a0 - lo, q = a0 - u;
    area += da * r / (6.0 * a0 * a0) * (u - lo) +
            8.0 / 15.0 * de * std::sqrt(r) * (p * p * std::sqrt(p) - q * q * std::sqrt(q));
  }
  return area;
}

// dH/dd [nN/nm]: A_H R/(3d³) for d ≥ a0, −2E*√R (a0 − d)^{1/2} below
double dmt_slope(double d, double modulus, double radius, double hamaker, double a0) {
  if (d >= a0) return hamaker * joule_per_nm_in_nN * radius / (3.0 * d * d * d);
  return -2.0 * modulus * std::sqrt(radius * (a0 - d));
}

class DmtModel final : public ForceLawModel {
 public:
  explicit DmtModel(const DmtLaw& law) : law_(law) {}
  std::string name() const override { return "dmt"; }
  double approach(double gap) const override { return law_.approach(gap); }
  double departure(double gap) const override { return law_.departure(gap); }
  bool has_slopes() const override { return true; }
  double approach_slope(double gap) const override {
    return dmt_slope(gap, law_.effective_modulus_approach, law_.tip_radius, law_.hamaker_approach,
                     law_.intermolecular_distance);
  }
  double departure_slope(double gap) const override {
    return dmt_slope(gap, law_.effective_modulus_departure, law_.tip_radius, law_.hamaker_departure,
                     law_.intermolecular_distance);
  }
  std::vector<double> switching_gaps() const override { return {law_.intermolecular_distance}; }
  bool branch_dependent(int region) const override {
    const bool moduli = law_.effective_modulus_approach != law_.effective_modulus_departure;
    const bool hamaker = law_.hamaker_approach != law_.hamaker_departure;
    return region == 0 ? moduli || hamaker : hamaker;
  }
  void require_dissipative() const override { law_.require_dissipative(); }
  double hysteresis_area(double lo, double hi) const override { return dmt_area(law_, lo, hi); }

 private:
  DmtLaw law_;
};
}  // namespace

double DmtLaw::approach(double d) const {
  return dmt(d, effective_modulus_approach, tip_radius, hamaker_approach, intermolecular_distance);
}
double DmtLaw::departure(double d) const {
  return dmt(d, effective_modulus_departure, tip_radius, hamaker_departure, intermolecular_distance);
}

ForceLaw::ForceLaw(DmtLaw law) : ForceLaw(std::make_shared<DmtModel>(law)) {}

}  // namespace afmkit::impact
