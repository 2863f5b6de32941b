#pragma once
// Units of the seed-2 control loop as users state them (docs/units.md, docs/theory-control.md#units): rates and
// frequencies in units of the rotation frequency Ω, delays and times in units of the rotation period T = 2π/Ω.
// The library itself works in rad/s and s (any consistent time unit: Ω = 1 rad/s means time in units of 1/Ω).
//   RotationUnits u(314.159);      // Ω = 314.159 rad/s (50 Hz)
//   u.rate(20)      -> 6283.2 rad/s    (γ = 20 Ω)
//   u.delay(0.1)    -> 0.002 s         (τ = 0.1 T)
//   u.in_omega(6283.2) -> 20,  u.in_periods(0.002) -> 0.1
#include <complex>
#include <string>

#include "afmkit/control/loop.hpp"

namespace afmkit::control {

/// Conversions between the user-facing units (Ω, T) and the library's (rad/s, s) for one rotation frequency.
class RotationUnits {
 public:
  /// Ω [rad/s] > 0 and finite; InvalidParameter("rotation_frequency", …) otherwise.
  explicit RotationUnits(double rotation_frequency);

  double rotation_frequency() const { return omega_; }  ///< Ω [rad/s]
  double period() const { return period_; }             ///< T = 2π/Ω [s]

  double rate(double in_omega) const { return in_omega * omega_; }         ///< units of Ω -> rad/s
  double delay(double in_periods) const { return in_periods * period_; }   ///< units of T -> s
  double in_omega(double rad_per_s) const { return rad_per_s / omega_; }   ///< rad/s -> units of Ω
  double in_periods(double seconds) const { return seconds / period_; }    ///< s -> units of T
  std::complex<double> in_omega(std::complex<double> s) const { return s / omega_; }  ///< a root s -> s/Ω

  /// Unit names (docs/units.md): user-facing rates and delays, and the library's.
  static constexpr const char* rate_unit = "Omega";
  static constexpr const char* delay_unit = "T";
  static constexpr const char* si_rate_unit = "rad/s";
  static constexpr const char* si_delay_unit = "s";

  friend bool operator==(const RotationUnits&, const RotationUnits&) = default;

 private:
  double omega_;
  double period_;
};

/// The loop in user-facing units, every number labelled: "bank N=10 alpha=0.1 Omega beta=-0.1 Omega K=20 Omega
/// rejected={1}; static plant gamma=20 Omega, tau=0.1 T (Omega = 1 rad/s)". (LoopSpec::describe() gives the
/// library's rad/s and s.)
std::string describe_in_rotation_units(const LoopSpec& loop);

}  // namespace afmkit::control
