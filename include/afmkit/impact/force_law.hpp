#pragma once
// Hysteresis interaction forces (seed-1 eq. 4, as corrected in MATH.md A.1):
//   H(d, ḋ) = H_a(d) while approaching (ḋ < 0), H_b(d) while departing (ḋ > 0), ½(H_a + H_b) at ḋ = 0.
// Sign convention: H > 0 is repulsive (pushes the two bodies apart). d is the gap between the bodies.
// In the tapping model (seed-1 eq. 8) d = x + l and h(x, ẋ) = −H(x + l, ẋ) (per unit mass).
#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace afmkit::impact {

/// Piecewise-linear hysteresis, seed-1 eqs. (10), (11), (26), in the tapping form
///   h = F_a + K_a·d (approach), h = F_b + K_b·d (departure) for d < 0, h = 0 for d ≥ 0,
/// i.e. H_a(d) = −(F_a + K_a d), H_b(d) = −(F_b + K_b d) for d < 0.
/// K_a, K_b ≥ 0 are stiffnesses (per unit mass in the tapping model); 0 ≤ F_a ≤ F_b are the attractive
/// offsets at the contact edge (F > 0 pulls the tip towards the sample).
/// The law dissipates energy at every penetration (area between the branches ≥ 0, seed-1 eq. 6) iff
/// K_b ≤ K_a and F_a ≤ F_b. An impact (ImpactProblem) rejects K_b > K_a unless `allow_energy_gain` is set;
/// the constructor itself accepts it (the tapping model may use such laws, see docs/conventions.md).
struct PiecewiseLinearLaw {
  double approach_stiffness;    // K_a
  double departure_stiffness;   // K_b
  double approach_adhesion;     // F_a
  double departure_adhesion;    // F_b
  bool allow_energy_gain = false;  ///< explicit opt-in for K_b > K_a (restitution e > 1, negative loss)

  /// Validates K_a ≥ 0, K_b ≥ 0, 0 ≤ F_a ≤ F_b, all finite.
  PiecewiseLinearLaw(double approach_stiffness, double departure_stiffness, double approach_adhesion = 0.0,
                     double departure_adhesion = 0.0, bool allow_energy_gain = false);
  static PiecewiseLinearLaw linear_repulsive(double stiffness);                        // eq. (10)
  static PiecewiseLinearLaw linear_hysteresis(double k_approach, double k_departure);  // eq. (11)
  static PiecewiseLinearLaw repulsive_attractive(double k_approach, double k_departure, double f_approach,
                                                 double f_departure);                  // eq. (26)
  /// K_b giving restitution e for an impulsive impact: K_b = e² K_a (MATH.md ext. E0). e ∈ (0, 1]; e > 1 only
  /// with allow_energy_gain. Computed as K_a − K_a(1 − e)(1 + e), the nearest to e² K_a for e → 1.
  static double departure_stiffness_for_restitution(double k_approach, double restitution,
                                                    bool allow_energy_gain = false);
  /// Throws InvalidParameter naming departure_stiffness when K_b > K_a and allow_energy_gain is not set.
  void require_dissipative() const;

  double approach(double gap) const { return gap < 0 ? -(approach_adhesion + approach_stiffness * gap) : 0.0; }
  double departure(double gap) const { return gap < 0 ? -(departure_adhesion + departure_stiffness * gap) : 0.0; }
};

/// DMT contact with van der Waals attraction (Derjaguin–Muller–Toporov), in the units AFM users state:
/// gap d and lengths in nm, force in nN, effective modulus E* in GPa, Hamaker constant in J.
///   d ≥ a0:  H(d) = −A_H R / (6 d²)
///   d < a0:  H(d) = −A_H R / (6 a0²) + (4/3) E* √R (a0 − d)^{3/2}
/// Approach and departure branches may use different E* and A_H (dissipation: E*_b ≤ E*_a, A_H,b ≥ A_H,a;
/// an impact rejects anything else unless `allow_energy_gain` is set).
struct DmtLaw {
  double effective_modulus_approach;   // E*_a [GPa]
  double effective_modulus_departure;  // E*_b [GPa]
  double tip_radius;                   // R [nm]
  double hamaker_approach;             // A_H,a [J]
  double hamaker_departure;            // A_H,b [J]
  double intermolecular_distance;      // a0 [nm]
  bool allow_energy_gain = false;      ///< explicit opt-in for E*_b > E*_a or A_H,b < A_H,a

  DmtLaw(double effective_modulus_approach, double effective_modulus_departure, double tip_radius,
         double hamaker_approach, double hamaker_departure, double intermolecular_distance,
         bool allow_energy_gain = false);
  /// Throws InvalidParameter naming departure_modulus / departure_hamaker when the law would create energy
  /// (E*_b > E*_a or A_H,b < A_H,a) and allow_energy_gain is not set.
  void require_dissipative() const;
  double approach(double gap) const;   // [nN]
  double departure(double gap) const;  // [nN]
};

/// User-supplied branches (any C++ callable). `switching_gaps` lists gaps where a branch is not smooth
/// (e.g. the contact edge); the integrators locate crossings of these as events.
struct CustomLaw {
  std::function<double(double)> approach;
  std::function<double(double)> departure;
  std::vector<double> switching_gaps;
  std::string name = "custom";
};

/// A hysteresis force law as a value: one of the kinds above, times a scale factor (used to convert a
/// physical law into the normalised per-unit-mass units of the tapping model).
class ForceLaw {
 public:
  using Kind = std::variant<PiecewiseLinearLaw, DmtLaw, CustomLaw>;
  ForceLaw(PiecewiseLinearLaw law);  // NOLINT(google-explicit-constructor)
  ForceLaw(DmtLaw law);              // NOLINT(google-explicit-constructor)
  ForceLaw(CustomLaw law);           // NOLINT(google-explicit-constructor)

  double approach(double gap) const;                   // scale · H_a(d)
  double departure(double gap) const;                  // scale · H_b(d)
  double force(double gap, double gap_rate) const;     // eq. (4)
  /// Gaps at which a branch is non-smooth (sorted); crossings are events for the integrators.
  const std::vector<double>& switching_gaps() const& { return switching_gaps_; }
  std::vector<double> switching_gaps() const&& { return switching_gaps_; }
  /// Non-null iff the law is piecewise linear (eqs. 10, 11, 26) — then the flow has a closed form.
  /// The returned coefficients already include the scale factor.
  const PiecewiseLinearLaw* piecewise_linear() const&;
  const PiecewiseLinearLaw* piecewise_linear() const&& = delete;  // would point into a temporary
  /// The same law with forces multiplied by `factor` (> 0).
  ForceLaw scaled(double factor) const;
  double scale() const { return scale_; }
  const Kind& kind() const& { return kind_; }
  Kind kind() const&& { return kind_; }
  /// Throws InvalidParameter when the law creates energy (area between the branches < 0 at some penetration)
  /// without its allow_energy_gain opt-in. Custom laws are not checked.
  void require_dissipative() const;
  std::string name() const;

 private:
  Kind kind_;
  double scale_ = 1.0;
  std::vector<double> switching_gaps_;
  std::shared_ptr<const PiecewiseLinearLaw> scaled_linear_;  // cached scaled copy for piecewise_linear()
  void refresh();
};

}  // namespace afmkit::impact
