#pragma once
// Hysteresis interaction forces (seed-1 eq. 4, as corrected in docs/theory-tapping.md#impact):
//   H(d, ḋ) = H_a(d) while approaching (ḋ < 0), H_b(d) while departing (ḋ > 0), ½(H_a + H_b) at ḋ = 0.
// Sign convention: H > 0 is repulsive (pushes the two bodies apart). d is the gap between the bodies.
// In the tapping model (seed-1 eq. 8) d = x + l and h(x, ẋ) = −H(x + l, ẋ) (per unit mass).
#include <algorithm>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace afmkit::impact {

/// How a law chooses between its approach and departure branches (docs/force-laws.md#hysteresis).
///   velocity — seed-1 eq. 4: H_a while ḋ < 0, H_b while ḋ > 0 (at every gap). The seed's laws.
///   contact  — a law with memory of contact: the tip is *free* until the gap reaches the contact gap d_c, then
///              *in contact* until the gap rises above the release gap d_r ≥ d_c (above which H_a = H_b). Free:
///              H_a whatever ḋ (no hysteresis, conservative); in contact: the velocity sign selects loading
///              (H_a, ḋ < 0) and unloading (H_b, ḋ > 0) as in eq. 4. A departure branch that differs from the
///              approach above d_c (adhesion neck, pull-off) thus acts only after an impact. Table laws.
enum class Hysteresis { velocity, contact };
const char* hysteresis_name(Hysteresis h);

/// Piecewise-linear hysteresis, seed-1 eqs. (10), (11), (26), in the tapping form
///   h = F_a + K_a·d (approach), h = F_b + K_b·d (departure) for d < 0, h = 0 for d ≥ 0,
/// i.e. H_a(d) = −(F_a + K_a d), H_b(d) = −(F_b + K_b d) for d < 0.
/// K_a, K_b ≥ 0 are stiffnesses (per unit mass in the tapping model); 0 ≤ F_a ≤ F_b are the attractive
/// offsets at the contact edge (F > 0 pulls the tip towards the sample).
/// The law dissipates energy at every penetration (area between the branches ≥ 0, seed-1 eq. 6) iff
/// K_b ≤ K_a and F_a ≤ F_b. An impact (ImpactProblem) and LawRegistry::build (every command) reject K_b > K_a unless
/// `allow_energy_gain` is set; the constructor itself accepts it (docs/conventions.md).
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
  /// K_b giving restitution e for an impulsive impact: K_b = e² K_a (seed-1 ext. E0). e ∈ (0, 1]; e > 1 only
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

/// What every force law is (the one interface that impact, simulation, shooting, harmonic balance, continuation
/// and sweeps take; docs/force-laws.md shows how to add one). Forces H > 0 are repulsive, in the law's own units.
///   H(d, ḋ) = H_a(d) − c(d)·ḋ while approaching (ḋ < 0), H_b(d) − c(d)·ḋ while departing (ḋ > 0),
///   ½(H_a + H_b) at ḋ = 0   (seed-1 eq. 4 with an optional Kelvin–Voigt term c(d) ≥ 0).
/// Between consecutive switching gaps every branch (and c) must be smooth; crossings of the switching gaps are
/// events located by the integrators and switching angles of the harmonic-balance quadrature.
class ForceLawModel {
 public:
  virtual ~ForceLawModel() = default;
  virtual std::string name() const = 0;
  virtual double approach(double gap) const = 0;   // H_a(d)
  virtual double departure(double gap) const = 0;  // H_b(d)
  /// dH_a/dd and dH_b/dd in closed form, when has_slopes() (else the integrators difference H within its region).
  /// Used by the variational equations and the witness rates: a law with slopes integrates faster.
  virtual bool has_slopes() const { return false; }
  virtual double approach_slope(double /*gap*/) const { return std::numeric_limits<double>::quiet_NaN(); }
  virtual double departure_slope(double /*gap*/) const { return std::numeric_limits<double>::quiet_NaN(); }
  /// Kelvin–Voigt coefficient c(d) ≥ 0 (force per unit gap rate); 0 unless has_damping().
  virtual double damping(double /*gap*/) const { return 0.0; }
  virtual bool has_damping() const { return false; }
  /// Whether the branches are smooth (C^∞) between switching gaps, as the 8th-order adaptive integrator assumes;
  /// false for laws only C¹ there (a monotone cubic through a measured table): integrated at 5th order instead.
  virtual bool smooth() const { return true; }
  /// Gaps at which a branch or c(d) is not smooth (any order; the ForceLaw sorts them).
  virtual std::vector<double> switching_gaps() const = 0;
  /// The gap below which tip and sample count as in contact (contact time, penetration, impacts): by default
  /// the lowest switching gap (0 for eqs. 10, 11, 26; a0 for DMT), NaN for a law without switching gaps.
  virtual double contact_gap() const {
    const auto g = switching_gaps();
    return g.empty() ? std::numeric_limits<double>::quiet_NaN() : *std::min_element(g.begin(), g.end());
  }
  /// Whether H_a and H_b may differ in region r (gaps between switching gap r−1 and r; region 0 lies below
  /// the lowest). Default: everywhere. A tighter answer saves velocity-zero guards.
  virtual bool branch_dependent(int /*region*/) const { return true; }
  /// The coefficients when the law is piecewise linear (eqs. 10, 11, 26): closed-form fast paths use them.
  virtual const PiecewiseLinearLaw* piecewise_linear() const { return nullptr; }
  /// Throws InvalidParameter naming the parameter when the law creates energy without its opt-in.
  virtual void require_dissipative() const {}
  /// ∫_lo^hi (H_a − H_b) dd in closed form when the law has one (seed-1 eq. 6); NaN: use quadrature.
  virtual double hysteresis_area(double /*lo*/, double /*hi*/) const { return std::numeric_limits<double>::quiet_NaN(); }
  /// The branch-selection semantics (see Hysteresis). A contact-aware law must list its contact gap and its
  /// release gap among its switching gaps (entering and leaving contact are events of the integrators).
  virtual Hysteresis hysteresis() const { return Hysteresis::velocity; }
  /// Contact-aware laws: the release gap d_r ≥ contact_gap(), the smallest gap above which H_a = H_b
  /// (contact ends when the gap rises above it). NaN for velocity-sign laws.
  virtual double release_gap() const { return std::numeric_limits<double>::quiet_NaN(); }
};

/// A hysteresis force law as a value: a shared immutable ForceLawModel, times a force scale factor (used to
/// convert a physical law into the normalised per-unit-mass units of the tapping model) and a rate scale for the
/// Kelvin–Voigt term. Copying is cheap.
class ForceLaw {
 public:
  explicit ForceLaw(std::shared_ptr<const ForceLawModel> model);
  ForceLaw(PiecewiseLinearLaw law);  // NOLINT(google-explicit-constructor)
  ForceLaw(DmtLaw law);              // NOLINT(google-explicit-constructor)
  ForceLaw(CustomLaw law);           // NOLINT(google-explicit-constructor)

  double approach(double gap) const { return scale_ * model_->approach(gap); }    // scale · H_a(d)
  double departure(double gap) const { return scale_ * model_->departure(gap); }  // scale · H_b(d)
  bool has_slopes() const { return model_->has_slopes(); }
  bool smooth() const { return model_->smooth(); }
  double approach_slope(double gap) const { return scale_ * model_->approach_slope(gap); }    // scale · dH_a/dd
  double departure_slope(double gap) const { return scale_ * model_->departure_slope(gap); }  // scale · dH_b/dd
  /// scale · rate scale · c(d): the Kelvin–Voigt coefficient in the scaled units (0 for laws without one).
  double damping(double gap) const { return has_damping_ ? damping_scale_ * model_->damping(gap) : 0.0; }
  bool has_damping() const { return has_damping_; }
  double force(double gap, double gap_rate) const;     // eq. (4) with the Kelvin–Voigt term
  /// H with the memory of contact: for a contact-aware law not `in_contact`, the approach branch whatever the
  /// rate (with the Kelvin–Voigt term); otherwise force(gap, gap_rate).
  double force(double gap, double gap_rate, bool in_contact) const;
  /// The branch-selection semantics (Hysteresis::velocity for the seed's laws).
  Hysteresis hysteresis() const { return hysteresis_; }
  bool contact_aware() const { return hysteresis_ == Hysteresis::contact; }
  /// Contact-aware laws: the release gap (≥ contact_gap(); a switching gap); NaN otherwise.
  double release_gap() const { return release_gap_; }
  /// Gaps at which a branch is non-smooth (sorted, distinct); crossings are events for the integrators.
  const std::vector<double>& switching_gaps() const& { return switching_gaps_; }
  std::vector<double> switching_gaps() const&& { return switching_gaps_; }
  /// The contact gap of the law (see ForceLawModel::contact_gap; NaN when the law has none).
  double contact_gap() const { return contact_gap_; }
  /// Whether the branches may differ between switching gaps region−1 and region (see ForceLawModel).
  bool branch_dependent(int region) const { return model_->branch_dependent(region); }
  /// Non-null iff the law is piecewise linear (eqs. 10, 11, 26) — then the flow has a closed form.
  /// The returned coefficients already include the scale factor.
  const PiecewiseLinearLaw* piecewise_linear() const&;
  const PiecewiseLinearLaw* piecewise_linear() const&& = delete;  // would point into a temporary
  /// The same law with forces multiplied by `force_factor` (> 0) and gap rates by `rate_factor` (> 0): a rate
  /// ḋ in the new units is ḋ·rate_factor in the old ones (the Kelvin–Voigt term scales by the product).
  ForceLaw scaled(double force_factor, double rate_factor = 1.0) const;
  double scale() const { return scale_; }
  const ForceLawModel& model() const& { return *model_; }
  const ForceLawModel& model() const&& = delete;  // would refer into a temporary
  /// Throws InvalidParameter when the law creates energy (area between the branches < 0 at some penetration)
  /// without its allow_energy_gain opt-in. Custom laws are not checked.
  void require_dissipative() const { model_->require_dissipative(); }
  /// scale · ∫_lo^hi (H_a − H_b) dd in closed form, NaN when the law has none.
  double hysteresis_area(double lo, double hi) const { return scale_ * model_->hysteresis_area(lo, hi); }
  std::string name() const { return model_->name(); }

 private:
  std::shared_ptr<const ForceLawModel> model_;
  double scale_ = 1.0;
  double damping_scale_ = 1.0;
  bool has_damping_ = false;
  double contact_gap_ = 0.0;
  Hysteresis hysteresis_ = Hysteresis::velocity;
  double release_gap_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> switching_gaps_;
  std::shared_ptr<const PiecewiseLinearLaw> scaled_linear_;  // cached scaled copy for piecewise_linear()
  void refresh();
};

/// A ForceLaw from a ForceLawModel type and its constructor arguments: make_law<HertzLaw>(1.0, 0.8, 10.0).
template <class Model, class... Args>
ForceLaw make_law(Args&&... args) {
  return ForceLaw(std::make_shared<const Model>(std::forward<Args>(args)...));
}

}  // namespace afmkit::impact
