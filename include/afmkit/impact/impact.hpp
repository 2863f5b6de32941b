#pragma once
// Two-body impact with hysteresis interaction forces (seed-1 §II, eqs. 1–6; docs/theory-tapping.md#impact).
//
//   m1 ẍ1 = F1(t) − H(d, ḋ),   m2 ẍ2 = F2(t) + H(d, ḋ),   d = x2 − x1 (gap)            (seed-1 eq. 1)
//   relative motion: d̈ = H(d, ḋ)/μ + F2/m2 − F1/m1,   μ = m1 m2/(m1 + m2) (reduced mass)
//
// H is a ForceLaw (H > 0 repulsive, acting on body 2): approach branch H_a while ḋ < 0, departure branch
// H_b while ḋ > 0 (seed-1 eq. 4 as corrected in docs/theory-tapping.md#impact). The impact interval [t_s, t_f] runs
// from the initial state (t_s = 0, gap d(t_s), ḋ(t_s) < 0) through the instant t̄ of minimum gap back to the same
// gap d(t_f) = d(t_s) (seed-1 §II). Piecewise-linear laws (eqs. 10, 11, 26) with constant external forces
// are solved in closed form with exact event times; any other law or time-dependent forcing is integrated
// (Dormand–Prince 5(4) with dense output and event location).
#include <functional>
#include <string>
#include <vector>

#include "afmkit/core/describe.hpp"

#include "afmkit/impact/force_law.hpp"

namespace afmkit::impact {

/// One material point P_i of seed-1 §II: mass m_i > 0, initial position x_i(t_s), initial velocity ẋ_i(t_s).
struct Body {
  double mass;
  double position;
  double velocity;
};

/// External forces F1(t), F2(t) of seed-1 eq. (1): a constant part plus an optional time-dependent part.
/// Isolated system: both zero (the default).
struct ExternalForces {
  double on_body1 = 0.0;                       // constant part of F1
  double on_body2 = 0.0;                       // constant part of F2
  std::function<double(double)> varying1;      // F1(t) − on_body1, if set
  std::function<double(double)> varying2;      // F2(t) − on_body2, if set

  bool isolated() const { return on_body1 == 0.0 && on_body2 == 0.0 && !varying1 && !varying2; }
  bool constant() const { return !varying1 && !varying2; }
  double force1(double t) const { return varying1 ? on_body1 + varying1(t) : on_body1; }
  double force2(double t) const { return varying2 ? on_body2 + varying2(t) : on_body2; }
};

/// A validated impact problem: m1, m2 > 0, finite initial state, approaching bodies (ḋ(t_s) = v2 − v1 < 0),
/// a dissipative law (K_b ≤ K_a, …) unless the law sets allow_energy_gain, and scales inside the double
/// range (m1 + m2, μ, ½ μ ḋ(t_s)² finite and normal).
class ImpactProblem {
 public:
  /// Throws InvalidParameter naming mass1/mass2/position1/…/relative_velocity/force1/force2, or
  /// departure_stiffness/departure_modulus/departure_hamaker for a law that creates energy.
  ImpactProblem(Body body1, Body body2, ForceLaw law, ExternalForces external = {});
  /// Isolated head-on impact with the centre of mass at rest at the origin: gap d(t_s) = `gap`,
  /// approach speed −ḋ(t_s) = `approach_speed` > 0.
  static ImpactProblem head_on(double mass1, double mass2, double approach_speed, double gap, ForceLaw law);

  const Body& body1() const& { return body1_; }
  Body body1() const&& { return body1_; }
  const Body& body2() const& { return body2_; }
  Body body2() const&& { return body2_; }
  const ForceLaw& law() const& { return law_; }
  ForceLaw law() const&& { return law_; }
  const ExternalForces& external() const& { return external_; }
  ExternalForces external() const&& { return external_; }
  double total_mass() const { return body1_.mass + body2_.mass; }
  double reduced_mass() const { return body1_.mass * (body2_.mass / total_mass()); }  // μ (no overflow of m1 m2)
  double initial_gap() const { return body2_.position - body1_.position; }            // d(t_s)
  double initial_gap_rate() const { return body2_.velocity - body1_.velocity; }       // ḋ(t_s) < 0

 private:
  Body body1_, body2_;
  ForceLaw law_;
  ExternalForces external_;
};

enum class ImpactMethod {
  automatic,    ///< closed form when possible (piecewise-linear law, constant external forces), else integrator
  closed_form,  ///< InvalidParameter("method") if not applicable
  integrator,   ///< always integrate eq. (1) numerically (any law)
};

/// One sample of the time history.
struct ImpactSample {
  double time;
  double gap;       // d
  double gap_rate;  // ḋ
  double force;     // H on the branch in use (approach before t̄, departure after)
  double position1, velocity1, position2, velocity2;
};

/// Numerical settings (validated by simulate_impact).
struct ImpactOptions {
  ImpactMethod method = ImpactMethod::automatic;
  /// Integrator error tolerances on the state scaled by L (lengths) and |ḋ(t_s)| (velocities), where
  /// L = max(|d(t_s)|, |switching gaps|) or 1 if those are all zero.
  double relative_tolerance = 1e-11;
  double absolute_tolerance = 1e-13;
  long max_steps = 1'000'000;  ///< integrator step budget -> NumericalFailure
  /// Time budget; 0 = automatic (10⁹ · L/|ḋ(t_s)|). Exceeding it -> NumericalFailure.
  double max_time = 0.0;
  /// Number of uniformly spaced samples of the time history on [t_s, t_f] (0 = none, else ≥ 2). The event
  /// instants (contact, minimum gap, separation) are added; at t̄ two rows give H_a and H_b.
  long history_points = 0;
  /// If set, every history sample is passed here (in time order) instead of being stored in
  /// ImpactResult::history, so memory does not grow with history_points. Without it the history is stored and
  /// simulate_impact refuses (InvalidParameter "history_points") a history larger than the available memory.
  std::function<void(const ImpactSample&)> on_sample{};

  /// The settings a user chooses, declared once (core/describe.hpp): key, help, unit, range; the defaults are the
  /// initializers above. simulate_impact checks them (check_fields) with the rest.
  template <class Archive, class Self>
  static void describe(Archive& a, Self& o) {
    a.choice("method", o.method, "solver: automatic (closed form for linear laws), closed_form, integrator",
             {{"automatic", ImpactMethod::automatic},
              {"closed_form", ImpactMethod::closed_form},
              {"integrator", ImpactMethod::integrator}});
    a.real("relative_tolerance", o.relative_tolerance, "integrator relative tolerance", "dimensionless",
           Range{0.0, 1e-2, true, false});
    a.real("absolute_tolerance", o.absolute_tolerance, "integrator absolute tolerance of the scaled state",
           "dimensionless", Range::positive());
  }
};

enum class ImpactOutcome {
  separated,  ///< the gap returned to d(t_s) with ḋ > 0: a complete impact
  captured,   ///< the bodies did not separate (attraction or external forces); no restitution defined
};

struct ImpactResult {
  ImpactOutcome outcome = ImpactOutcome::separated;
  std::string capture_reason;  ///< why the bodies did not separate (empty if separated)
  std::string method;          ///< "closed_form" or "integrator"
  double reduced_mass = 0;     ///< μ = m1 m2 / (m1 + m2)

  double start_time = 0;       ///< t_s (initial instant)
  double minimum_time = 0;     ///< t̄, instant of minimum gap (ḋ = 0)
  double end_time = 0;         ///< t_f (gap back to d(t_s)); for a capture, the instant it was detected
  double reference_gap = 0;    ///< d(t_s) = d(t_f)
  double minimum_gap = 0;      ///< d(t̄)
  double contact_gap = 0;      ///< ForceLaw::contact_gap (0 piecewise-linear and Hertz, a0 DMT/LJ); NaN if none
  double max_penetration = 0;  ///< contact_gap − minimum_gap (NaN if the law has no switching gap)
  bool contact = false;        ///< the gap went below contact_gap (always true if the law has no switching gap)
  double contact_start = 0;    ///< first crossing of contact_gap (t_s if started inside); NaN without contact
  double contact_end = 0;      ///< crossing back (NaN without contact or if captured)
  double contact_duration = 0;

  double approach_gap_rate = 0;   ///< ḋ(t_s) < 0
  double departure_gap_rate = 0;  ///< ḋ(t_f) (NaN if captured)
  double restitution = 0;         ///< e = −ḋ(t_f)/ḋ(t_s), seed-1 eq. (2) (NaN if captured)
  /// 1 − e, computed without cancellation (closed form: from the energy balance), so nearly elastic impacts
  /// keep relative accuracy (NaN if captured)
  double restitution_deficit = 0;
  double kinetic_energy_before = 0;
  double kinetic_energy_after = 0;
  double kinetic_energy_loss = 0;      ///< simulated: KE(t_s) − KE(t_f) (closed form: relative part exact, eq. 6)
  double energy_loss_restitution = 0;  ///< (1 − e)(1 + e) μ/2 ḋ(t_s)², seed-1 eq. (3)
  double energy_loss_area = 0;         ///< ∫_{d(t̄)}^{d(t_s)} (H_a − H_b) dξ, seed-1 eq. (6) (closed form or quadrature)
  /// Check of the solution: kinetic-energy loss of the relative motion from the solver's own final state
  /// (arcs, or the integrated state) minus the eq. (6) area. With constant external forces the reported
  /// ḋ(t_f), e, 1 − e and losses come from the energy balance ½ μ ḋ(t_f)² = ½ μ ḋ(t_s)² − area at the solved
  /// d(t̄), which stays relatively accurate as e → 1; this residual shows how far the raw state was from it
  /// (~ε KE for the closed form, ~ the tolerance × KE for the integrator). NaN if captured or if the external
  /// forces depend on time (then the integrated state is reported as is).
  double energy_balance_residual = 0;
  double peak_force = 0;               ///< max H over the impact (repulsive peak); integrator: over steps and events
  double min_force = 0;                ///< min H over the impact (negative: strongest attraction)

  Body body1_after{};  ///< state at t_f (or at the capture instant)
  Body body2_after{};
  long steps = 0;      ///< integrator steps (closed form: number of analytic segments)
  std::vector<ImpactSample> history;
};

/// Simulate one impact. Throws InvalidParameter for bad options, NumericalFailure when the approach
/// never stops (no repulsion) or a step/time budget is exhausted.
ImpactResult simulate_impact(const ImpactProblem& problem, const ImpactOptions& options = {});

/// Energy dissipated by the hysteresis, ∫_{minimum_gap}^{reference_gap} (H_a − H_b) dξ (seed-1 eq. 6).
/// Piecewise-linear and DMT laws: closed form written in the branch differences K_a − K_b, F_b − F_a,
/// E*_a − E*_b, A_H,b − A_H,a (relative accuracy also when the branches nearly coincide, e → 1). Custom laws:
/// adaptive Gauss–Kronrod quadrature of H_a − H_b split at the switching gaps, converged relative to the
/// area itself or to the rounding floor ε ∫(|H_a| + |H_b|) of the branch values, whichever is larger.
/// A contact-aware law (docs/force-laws.md#hysteresis) loses nothing when minimum_gap lies above its contact gap.
double hysteresis_energy_loss(const ForceLaw& law, double minimum_gap, double reference_gap);

/// Kinetic-energy loss of an isolated impact with restitution e (seed-1 eq. 3, t_i -> t_s):
/// (1 − e²) m1 m2 / (2 (m1 + m2)) · (ẋ1(t_s) − ẋ2(t_s))².
double restitution_energy_loss(double mass1, double mass2, double relative_velocity, double restitution);

const char* to_string(ImpactOutcome outcome);

}  // namespace afmkit::impact
