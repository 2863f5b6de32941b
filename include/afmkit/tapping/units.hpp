#pragma once
// Physical units as AFM users state them, and their conversion to the normalised model of seed-1 eq. (8).
//
// Normalised units (the papers' form): time unit t (= 1/ω_n for ω_n = 1), length unit L (any; nm when the model
// is built from physical units), interaction and drive "forces" per unit mass in L/t² (docs/units.md). A physical
// run builds the normalised model with ω_n = 1 and L = nm; with cantilever spring constant k [N/m]:
//   force      F [nN]  ↔  h = F / k            (1 nN / (1 N/m) = 1 nm)
//   stiffness  k_s [N/m] ↔ K = k_s / k          (in units of ω_n², e.g. K_a)
//   energy     E [aJ]  =  k · E_model           (k [N/m] · 1 nm² = 1e-18 J = 1 aJ)
//   time       t [s]   =  t_model / (2π f0)     (f0 = resonance frequency)
//   drive      Γ = A_free / |L(iω)|             (A_free = free amplitude at the drive frequency, nm)
#include "afmkit/tapping/model.hpp"

namespace afmkit::tapping {

/// Multiply a model quantity by these factors to obtain it in the user's units, named by the *_unit fields
/// (docs/units.md). Default: the normalised model (length unit L, time unit t; forces and energies per unit mass).
struct UnitScales {
  double length = 1.0;  // nm per model length unit
  double force = 1.0;   // nN per model force unit (normalised: 1)
  double energy = 1.0;  // aJ per model energy unit (normalised: 1)
  double time = 1.0;    // s per model time unit (normalised: 1)
  const char* length_unit = "L";
  const char* force_unit = "L/t^2";
  const char* energy_unit = "L^2/t^2";
  const char* time_unit = "t";
};

/// The cantilever and drive as measured on an instrument. The constructor takes the settings in the ranges of the
/// command line and Python (tapping/cantilever_limits.hpp; InvalidParameter naming the key and the range otherwise).
struct PhysicalCantilever {
  double spring_constant;      // k [N/m] in (0, 1e6]
  double resonance_frequency;  // f0 [kHz] in (0, 1e7]
  double quality_factor;       // Q in (0, 1e9]
  double free_amplitude;       // A_free [nm] in (0, 1e6], free oscillation amplitude at the drive frequency
  double frequency_ratio;      // ω/ω_n > 0

  PhysicalCantilever(double spring_constant, double resonance_frequency, double quality_factor,
                     double free_amplitude, double frequency_ratio);  // validated
  Cantilever cantilever() const { return {1.0, quality_factor}; }   // normalised: ω_n = 1
  Drive drive() const;                                               // Γ from the free amplitude
  UnitScales scales() const;
  double normalised_stiffness(double stiffness_n_per_m) const { return stiffness_n_per_m / spring_constant; }
  double normalised_force(double force_nN) const { return force_nN / spring_constant; }
  /// A force law in physical units (gap nm, force nN, gap rate nm/s) as the model's per-unit-mass law
  /// (force / k; a model rate is 2π f0 times a physical one, which scales a Kelvin–Voigt term).
  impact::ForceLaw normalised_law(const impact::ForceLaw& physical) const;
};

}  // namespace afmkit::tapping
