#pragma once
// The tapping cantilever as a Lur'e system (seed-1 eqs. 8–9), in normalised form:
//   ẍ + 2ξω_n ẋ + ω_n² x = Γ cos(ωt) − h(x, ẋ),    h(x, ẋ) = −H(x + l, ẋ)
// x: tip position (0 = rest position without sample), the sample surface at x = −l (l = separation),
// H: the hysteresis force law (impact::ForceLaw, per unit mass), positive = repulsive.
// Phase convention of every result: x(t) ≈ A + B cos(ωt − φ) (φ = phase lag, radians; φ = π/2 for the free
// response at resonance).
#include <complex>

#include "afmkit/impact/force_law.hpp"

namespace afmkit::tapping {

/// The linear block L(s) = 1/(s² + 2ξω_n s + ω_n²) (seed-1 eq. 9). Q = 1/(2ξ).
struct Cantilever {
  double natural_frequency;  // ω_n > 0
  double quality_factor;     // Q > 0

  Cantilever(double natural_frequency, double quality_factor);  // validated
  double damping_ratio() const { return 0.5 / quality_factor; }  // ξ
  /// L(s) of eq. (9).
  std::complex<double> transfer(std::complex<double> s) const;
  double static_gain() const { return 1.0 / (natural_frequency * natural_frequency); }  // L(0)
};

/// Sinusoidal drive u(t) = Γ cos(ωt) (force per unit mass).
struct Drive {
  double amplitude;  // Γ > 0
  double frequency;  // ω > 0
  Drive(double amplitude, double frequency);  // validated
  double period() const;
};

/// Cantilever + drive + tip–sample force law + separation l.
struct TappingModel {
  Cantilever cantilever;
  Drive drive;
  impact::ForceLaw law;
  double separation;  // l (finite)

  TappingModel(Cantilever cantilever, Drive drive, impact::ForceLaw law, double separation);  // validated
  /// h(x, ẋ) of eq. (8): the interaction term on the right-hand side enters as −h.
  double interaction(double x, double velocity) const { return -law.force(x + separation, velocity); }
  /// Free-oscillation amplitude Γ|L(iω)|.
  double free_amplitude() const;
  double period() const { return drive.period(); }
  TappingModel with_separation(double l) const;
};

}  // namespace afmkit::tapping
