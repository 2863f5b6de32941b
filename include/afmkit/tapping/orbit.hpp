#pragma once
// Observables of a periodic orbit (first harmonic, offset, phase, higher harmonics, contact, forces, energy)
// and the search for every periodic orbit at one separation.
//
// Phase convention: x(t) ≈ A + B cos(ωt − φ) for the drive Γ cos ωt (φ = π/2 for the free response at
// resonance). Harmonics are Fourier coefficients at kω over the whole orbit (n drive periods for a period-n
// orbit), computed by Gauss–Legendre quadrature on every smooth segment between events (exact to rounding).
// Energy per drive period (per unit mass): drive work W = ∫ Γ cos(ωt) ẋ dt, viscous loss ∫ 2ξω_n ẋ² dt,
// contact loss ∫ h(x, ẋ) ẋ dt (energy taken by the sample); for a periodic orbit W = viscous + contact.
#include <array>
#include <string>
#include <vector>

#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/transient.hpp"

namespace afmkit::tapping {

struct OrbitMetrics {
  double amplitude = 0.0;  // B: first harmonic
  double offset = 0.0;     // A: mean of x
  double phase = 0.0;      // φ [rad] in (−π, π]
  std::array<double, 4> harmonics{};  // amplitudes of harmonics 2, 3, 4, 5 (|c_k|, same normalisation as B)
  double contact_fraction = 0.0;  // fraction of time with x + l below the lowest switching gap
  double peak_force = 0.0;        // max over the orbit of H (tip–sample force, positive = repulsive)
  double min_gap = 0.0;           // min over the orbit of x + l
  double drive_work = 0.0;            // per drive period
  double viscous_dissipation = 0.0;   // per drive period
  double contact_dissipation = 0.0;   // per drive period
  double energy_dissipated() const { return viscous_dissipation + contact_dissipation; }
  long impacts_per_period_multiple = 0;  // contacts during one orbit (n drive periods)
  double sticking_duration = 0.0;        // time spent sticking during one orbit
};

/// Evaluate the observables of `orbit` by simulating it once (period_multiple drive periods).
OrbitMetrics analyse_orbit(const TappingModel& model, const PeriodicOrbit& orbit,
                           const SimulationOptions& options = {});

/// Where an orbit came from.
enum class OrbitSource { hb_free, hb_plus, hb_minus, transient, previous, continuation };
const char* orbit_source_name(OrbitSource source);

struct FoundOrbit {
  OrbitSource source;
  PeriodicOrbit orbit;
  OrbitMetrics metrics;
};

struct OrbitSearchOptions {
  ShootingOptions shooting;
  TransientOptions transient;
  bool from_harmonic_balance = true;  // shoot from each HB solution (piecewise-linear laws only)
  bool from_transient = true;         // settle a transient from rest and from the free response, then shoot
  bool parallel = true;               // OpenMP over the candidates
  /// Two converged orbits are the same when their initial states differ by less than this (relative).
  double duplicate_tolerance = 1e-6;
};

struct OrbitSearchResult {
  std::vector<HbPoint> harmonic_balance;  // every HB solution (empty for non piecewise-linear laws)
  std::vector<FoundOrbit> orbits;         // distinct orbits, by increasing amplitude
  std::vector<TransientOutcome> transients;  // what each transient settled to (incl. non-periodic)
};

/// Every periodic orbit found at model.separation (shooting from every HB solution, and from transients).
OrbitSearchResult find_orbits(const TappingModel& model, const OrbitSearchOptions& options = {});

}  // namespace afmkit::tapping
