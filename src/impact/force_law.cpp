#include "afmkit/impact/force_law.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::impact {

PiecewiseLinearLaw::PiecewiseLinearLaw(double ka, double kb, double fa, double fb, bool allow_gain)
    : approach_stiffness(validate::non_negative("approach_stiffness", ka)),
      departure_stiffness(validate::non_negative("departure_stiffness", kb)),
      approach_adhesion(validate::non_negative("approach_adhesion", fa)),
      departure_adhesion(validate::finite("departure_adhesion", fb)),
      allow_energy_gain(allow_gain) {
  validate::require(fb >= fa, "departure_adhesion", fb,
                    fmt::format(">= approach_adhesion = {} (0 <= F_a <= F_b, seed-1 eq. 26)", fa));
}

void PiecewiseLinearLaw::require_dissipative() const {
  // Area between the branches (seed-1 eq. 6) at penetration δ: (F_b − F_a)δ + ½(K_a − K_b)δ² ≥ 0 for all
  // δ ≥ 0 iff F_b ≥ F_a (always enforced) and K_b ≤ K_a.
  if (allow_energy_gain || departure_stiffness <= approach_stiffness) return;
  throw InvalidParameter(
      "departure_stiffness",
      fmt::format("departure_stiffness = {} must be <= approach_stiffness = {} (a hysteresis law dissipates energy; "
                  "set allow_energy_gain = true to allow e > 1)",
                  departure_stiffness, approach_stiffness));
}

PiecewiseLinearLaw PiecewiseLinearLaw::linear_repulsive(double k) { return {k, k, 0.0, 0.0}; }
PiecewiseLinearLaw PiecewiseLinearLaw::linear_hysteresis(double ka, double kb) { return {ka, kb, 0.0, 0.0}; }
PiecewiseLinearLaw PiecewiseLinearLaw::repulsive_attractive(double ka, double kb, double fa, double fb) {
  return {ka, kb, fa, fb};
}
double PiecewiseLinearLaw::departure_stiffness_for_restitution(double ka, double e, bool allow_gain) {
  validate::non_negative("approach_stiffness", ka);
  validate::require(std::isfinite(e) && e > 0 && (e <= 1 || allow_gain), "restitution", e,
                    allow_gain ? "> 0 (finite)"
                               : "in (0, 1] (e > 1 creates energy; set allow_energy_gain = true to allow it)");
  // K_b = e² K_a written as K_a − K_a(1 − e)(1 + e): for e ∈ [½, 1] 1 − e is exact, so K_a − K_b keeps its
  // relative accuracy as e → 1 (the loss (1 − e²) μ v²/2 of seed-1 eq. 3 is proportional to it).
  const double kb = e >= 0.5 && e <= 1.0 ? ka - ka * ((1.0 - e) * (1.0 + e)) : e * e * ka;
  if (!std::isfinite(kb))
    throw InvalidParameter("restitution", fmt::format("restitution = {} with approach_stiffness = {} gives a "
                                                      "departure stiffness e^2 K_a beyond the double range",
                                                      e, ka));
  return kb;
}

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
// force in nN for gap d [nm], modulus [GPa], radius [nm], Hamaker [J]: J/nm = 1e18 nN
double dmt(double d, double modulus, double radius, double hamaker, double a0) {
  constexpr double joule_per_nm_in_nN = 1e18;
  if (d >= a0) return -hamaker * joule_per_nm_in_nN * radius / (6.0 * d * d);
  const double delta = a0 - d;
  return -hamaker * joule_per_nm_in_nN * radius / (6.0 * a0 * a0) +
         4.0 / 3.0 * modulus * std::sqrt(radius) * delta * std::sqrt(delta);
}
}  // namespace

double DmtLaw::approach(double d) const {
  return dmt(d, effective_modulus_approach, tip_radius, hamaker_approach, intermolecular_distance);
}
double DmtLaw::departure(double d) const {
  return dmt(d, effective_modulus_departure, tip_radius, hamaker_departure, intermolecular_distance);
}

ForceLaw::ForceLaw(PiecewiseLinearLaw law) : kind_(law) { refresh(); }
ForceLaw::ForceLaw(DmtLaw law) : kind_(law) { refresh(); }
ForceLaw::ForceLaw(CustomLaw law) : kind_(std::move(law)) {
  const auto& c = std::get<CustomLaw>(kind_);
  if (!c.approach || !c.departure) throw InvalidParameter("force_law", "custom force law: both branches must be set");
  refresh();
}

void ForceLaw::refresh() {
  switching_gaps_.clear();
  scaled_linear_.reset();
  if (auto* p = std::get_if<PiecewiseLinearLaw>(&kind_)) {
    switching_gaps_ = {0.0};
    scaled_linear_ = std::make_shared<PiecewiseLinearLaw>(p->approach_stiffness * scale_, p->departure_stiffness * scale_,
                                                          p->approach_adhesion * scale_, p->departure_adhesion * scale_,
                                                          p->allow_energy_gain);
  } else if (auto* d = std::get_if<DmtLaw>(&kind_)) {
    switching_gaps_ = {d->intermolecular_distance};
  } else {
    switching_gaps_ = std::get<CustomLaw>(kind_).switching_gaps;
    std::sort(switching_gaps_.begin(), switching_gaps_.end());
  }
}

double ForceLaw::approach(double gap) const {
  return scale_ * std::visit([gap](const auto& k) { return k.approach(gap); }, kind_);
}
double ForceLaw::departure(double gap) const {
  return scale_ * std::visit([gap](const auto& k) { return k.departure(gap); }, kind_);
}
double ForceLaw::force(double gap, double rate) const {
  if (rate < 0) return approach(gap);
  if (rate > 0) return departure(gap);
  return 0.5 * (approach(gap) + departure(gap));
}

const PiecewiseLinearLaw* ForceLaw::piecewise_linear() const& { return scaled_linear_.get(); }

void ForceLaw::require_dissipative() const {
  if (const auto* p = std::get_if<PiecewiseLinearLaw>(&kind_)) p->require_dissipative();  // user's units
  else if (const auto* d = std::get_if<DmtLaw>(&kind_)) d->require_dissipative();
}

ForceLaw ForceLaw::scaled(double factor) const {
  validate::positive("force_scale", factor);
  ForceLaw out = *this;
  out.scale_ = scale_ * factor;
  out.refresh();
  return out;
}

std::string ForceLaw::name() const {
  struct V {
    std::string operator()(const PiecewiseLinearLaw& p) const {
      if (p.approach_adhesion == 0 && p.departure_adhesion == 0)
        return p.approach_stiffness == p.departure_stiffness ? "linear_repulsive" : "linear_hysteresis";
      return "repulsive_attractive";
    }
    std::string operator()(const DmtLaw&) const { return "dmt"; }
    std::string operator()(const CustomLaw& c) const { return c.name; }
  };
  return std::visit(V{}, kind_);
}

}  // namespace afmkit::impact
