#pragma once
// Built-in contact laws beyond the paper's piecewise-linear ones, in the units AFM users state: gap d in nm,
// force in nN (H > 0 repulsive), effective modulus E* in GPa, tip radius R in nm, Hamaker constant A_H in J,
// adhesion energy γ in J/m², viscosity η in Pa·s, gap rate in nm/s. docs/force-laws.md gives every formula.
// Each is a ForceLawModel; wrap it with make_law<…>(…) to obtain a ForceLaw.
#include <memory>
#include <string>
#include <vector>

#include "afmkit/impact/force_law.hpp"

namespace afmkit::impact {

/// Hertz contact without attraction:  H(d) = (4/3) E* √R (−d)^{3/2} for d < 0, 0 for d ≥ 0.
/// Approach and departure moduli may differ (dissipative iff E*_b ≤ E*_a).
class HertzLaw final : public ForceLawModel {
 public:
  HertzLaw(double effective_modulus_approach, double effective_modulus_departure, double tip_radius,
           bool allow_energy_gain = false);  // validated: E* > 0, R > 0
  std::string name() const override { return "hertz"; }
  double approach(double gap) const override;
  double departure(double gap) const override;
  bool has_slopes() const override { return true; }
  double approach_slope(double gap) const override;   // −2E*_a √R (−d)^{1/2} in contact
  double departure_slope(double gap) const override;  // −2E*_b √R (−d)^{1/2} in contact
  std::vector<double> switching_gaps() const override { return {0.0}; }
  bool branch_dependent(int region) const override { return region == 0 && modulus_a_ != modulus_b_; }
  void require_dissipative() const override;
  double hysteresis_area(double lo, double hi) const override;

 private:
  double modulus_a_, modulus_b_, radius_;
  bool allow_gain_;
};

/// JKR-like adhesion hysteresis: different adhesion on approach and retract. The tip approaches on the DMT curve
/// (van der Waals −A_H R/(6d²) for d ≥ a0; in contact Hertz plus the constant −A_H R/(6a0²)) but retracts from
/// contact with the JKR pull-off force F_pull = (3/2)πγR: H_b = −F_pull + (4/3)E*√R(a0 − d)^{3/2} for d < a0,
/// H_b = H_a (van der Waals) for d ≥ a0 — the neck breaks at the contact edge (a switching gap: the retract
/// force jumps there). Dissipative iff F_pull ≥ A_H R/(6a0²); the loss per touch is (F_pull − A_H R/(6a0²))·δ_max.
class AdhesionHysteresisLaw final : public ForceLawModel {
 public:
  AdhesionHysteresisLaw(double effective_modulus, double tip_radius, double hamaker, double intermolecular_distance,
                        double adhesion_energy, bool allow_energy_gain = false);  // validated
  std::string name() const override { return "jkr"; }
  double approach(double gap) const override;
  double departure(double gap) const override;
  bool has_slopes() const override { return true; }
  double approach_slope(double gap) const override;
  double departure_slope(double gap) const override;
  std::vector<double> switching_gaps() const override { return {a0_}; }
  bool branch_dependent(int region) const override { return region == 0; }
  void require_dissipative() const override;
  double hysteresis_area(double lo, double hi) const override;
  double pull_off_force() const { return pull_off_; }  // F_pull [nN]

 private:
  double modulus_, radius_, hamaker_, a0_, pull_off_;
  bool allow_gain_;
};

/// Lennard-Jones sphere–plane interaction (integrated 6–12 potential):
///   H(d) = (A_H R/6) (−1/d² + a0⁶/d⁸) for d ≥ a0/2 (zero force at d = a0),
/// continued below a0/2 by its tangent (finite force at d ≤ 0). Same on both branches (conservative).
class LennardJonesLaw final : public ForceLawModel {
 public:
  LennardJonesLaw(double tip_radius, double hamaker, double intermolecular_distance);  // validated
  std::string name() const override { return "lennard_jones"; }
  double approach(double gap) const override;
  double departure(double gap) const override { return approach(gap); }
  bool has_slopes() const override { return true; }
  double approach_slope(double gap) const override;  // (A_H R/6)(2/d³ − 8a0⁶/d⁹), constant below a0/2
  double departure_slope(double gap) const override { return approach_slope(gap); }
  std::vector<double> switching_gaps() const override { return {0.5 * a0_}; }
  double contact_gap() const override { return a0_; }  // where the force turns repulsive
  bool branch_dependent(int) const override { return false; }
  double hysteresis_area(double, double) const override { return 0.0; }

 private:
  double coefficient_, a0_;  // A_H R/6 [nN·nm]
  double force_at(double d) const;
};

/// Kelvin–Voigt viscoelastic DMT contact: the DMT law (one modulus, one Hamaker constant) plus the viscous
/// term −c(d)·ḋ with c(d) = η √(R (a0 − d)) in contact (d < a0), 0 outside (c in nN·s/nm: 1e-9 η[Pa·s] √(R δ)[nm]).
class KelvinVoigtLaw final : public ForceLawModel {
 public:
  KelvinVoigtLaw(double effective_modulus, double tip_radius, double hamaker, double intermolecular_distance,
                 double viscosity);  // validated
  std::string name() const override { return "kelvin_voigt"; }
  double approach(double gap) const override;
  double departure(double gap) const override { return approach(gap); }
  double damping(double gap) const override;
  bool has_damping() const override { return true; }
  std::vector<double> switching_gaps() const override { return {a0_}; }
  bool branch_dependent(int) const override { return false; }
  double hysteresis_area(double, double) const override { return 0.0; }

 private:
  double modulus_, radius_, hamaker_, a0_, viscosity_;
};

}  // namespace afmkit::impact
