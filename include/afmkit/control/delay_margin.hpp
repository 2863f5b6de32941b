#pragma once
// Delay margin of the seed-2 loop (seed-2 ext. E1/E2, docs/theory-control.md#delay-margin): the interval of measurement
// delays τ around a reference delay (0 for the plain loop; the model delay τ̂ for the Smith predictor) in which the
// closed loop stays exponentially stable.
//
// For every loop of loop.hpp, Δ(s; τ) = X(s) + Y(s) e^{−sτ} with X, Y independent of τ. A root crosses the
// imaginary axis at s = iν (ν > 0) for delay τ iff
//   |X(iν)| = |Y(iν)|                          (crossing frequencies; E1 for one oscillator, E2 in general)
//   e^{−iντ} = −X(iν)/Y(iν)                    (phase condition: τ = (−arg(−X/Y) + 2πm)/ν, m ∈ ℤ).
// s = 0 cannot cross (Δ(0; τ) does not depend on τ). The crossing frequencies are bracketed on a grid of
// (0, ν_max] (ν_max from the proven root-free bound of spectrum.hpp: |Y| < |X| beyond it) and refined by
// TOMS 748; the margin is the nearest crossing delay on each side of the reference.
// One oscillator with the static plant (κ = K/γ): the crossing frequencies solve the quadratic in ν²
//   ν⁴ − (2Ω² + κ²a²) ν² + Ω⁴ − κ²b²Ω² = 0,   e^{−iντ} = (ν² − Ω²)/(κ(iaν − bΩ))      (seed-2 ext. E1).
#include <limits>
#include <string>
#include <vector>

#include "afmkit/control/loop.hpp"

namespace afmkit::control {

struct DelayCrossing {
  double frequency = 0;     ///< ν > 0 [rad/s]: roots at ±iν
  double first_delay = 0;   ///< smallest τ > 0 with these roots on the axis
  double delay_period = 0;  ///< 2π/ν: the crossings repeat at first_delay + m·delay_period
};

struct DelayMargin {
  double reference_delay = 0;    ///< τ where stability is required (0 plain loop, τ̂ Smith predictor)
  bool stable_at_reference = false;
  int unstable_at_reference = 0; ///< unstable roots at the reference delay (−1: infinitely many)
  bool marginal_at_reference = false;
  /// Stability interval (lower, upper) containing the reference delay. Plain loop: lower = 0, upper = τ_c.
  /// +inf: no crossing on that side. NaN when the loop is not stable at the reference delay.
  double lower = std::numeric_limits<double>::quiet_NaN();
  double upper = std::numeric_limits<double>::quiet_NaN();
  double lower_frequency = std::numeric_limits<double>::quiet_NaN();  ///< crossing frequency at `lower`
  double upper_frequency = std::numeric_limits<double>::quiet_NaN();  ///< crossing frequency at `upper`
  std::vector<DelayCrossing> crossings;
  bool upper_exceeds_period = false;  ///< τ_c ≥ T: outside the paper's assumption τ < T (flag, not an error)
  std::string method;                 ///< "E1" (one-oscillator closed form) or "E2" (crossing-frequency search)
  std::string note;
};

struct MarginOptions {
  double reference_delay = std::numeric_limits<double>::quiet_NaN();  ///< NaN: 0 (plain) or τ̂ (Smith)
  double max_frequency = std::numeric_limits<double>::quiet_NaN();    ///< NaN: proven bound
  int grid_points_per_omega = 64;    ///< bracketing grid density
  bool use_closed_form = true;       ///< E1 for the single oscillator with static plant
  bool check_reference = true;       ///< certify stability at the reference delay (argument principle)
};

/// Delay margin of the loop (its own delay is ignored: the margin is a property of the τ-family).
DelayMargin delay_margin(const LoopSpec& loop, const MarginOptions& options = {});

/// Crossing frequencies ν > 0 with |X(iν)| = |Y(iν)| (E2), sorted.
std::vector<DelayCrossing> delay_crossings(const LoopSpec& loop, const MarginOptions& options = {});

/// seed-2 ext. E1 closed form: crossings of the single oscillator (5)–(6) with the static plant (3),
/// κ = K/γ. Validated: finite a, b; κ, Ω > 0.
std::vector<DelayCrossing> single_oscillator_crossings(double a, double b, double gain_ratio,
                                                       double rotation_frequency);

}  // namespace afmkit::control
