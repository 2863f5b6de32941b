#pragma once
// A cantilever with up to three flexural eigenmodes (docs/theory-tapping.md#more-than-one-eigenmode), in the
// normalised units of model.hpp (time 1/ω_1 when built from physical units, forces per unit mass of mode 1):
//   q̈_i + 2ξ_iω_i q̇_i + ω_i² q_i = ρ [ F_i(t) − β_i h(x + l, ẋ) ],   i = 1..M (M ≤ 3)
//   x = y_b(t) + Σ_i q_i   (tip position above its rest position; y_b: base motion, 0 for direct excitation)
//   F_i(t) = Σ_d β_i Γ_d cos ω_d t            (direct: a force at the tip, per unit mode-1 mass)
//   F_i(t) = Σ_d γ_i ω_d² Y_d cos ω_d t,  y_b = Σ_d Y_d cos ω_d t   (base / acoustic excitation)
// β_i = m_1/m_i (modal mass ratio of tip-normalised modes: β_i = (k_1/k_i)(ω_i/ω_1)², 1 for a uniform beam),
// γ_i: the mode's participation in a base motion (tip-normalised Euler–Bernoulli modes: 1.566, −0.867, 0.509),
// ρ = 1/(1 + μ): a liquid's added mass μ m_i on every mode (and fluid damping, see Medium).
// Euler–Bernoulli rectangular cantilever (Melcher, Hu, Raman, Appl. Phys. Lett. 91, 053101 (2007)):
//   ω_i/ω_1 = (λ_i/λ_1)²,  k_i/k_1 = (λ_i/λ_1)⁴,  1 + cos λ cosh λ = 0 (λ_1..3 = 1.8751, 4.6941, 7.8548).
#include <array>
#include <complex>
#include <limits>
#include <vector>

#include "afmkit/impact/force_law.hpp"
#include "afmkit/tapping/model.hpp"

namespace afmkit::tapping {

inline constexpr int kMaxEigenmodes = 3;

/// One flexural eigenmode (normalised units).
struct Eigenmode {
  double natural_frequency;  // ω_i > 0 (in air / vacuum: the medium is applied by MultiModeModel)
  double quality_factor;     // Q_i > 0 (in air / vacuum)
  double mass_ratio;         // β_i = m_1/m_i = (k_1/k_i)(ω_i/ω_1)² > 0 (1 for the first mode)
  double participation;      // γ_i: base-excitation participation of the tip-normalised mode (finite)
  Eigenmode(double natural_frequency, double quality_factor, double mass_ratio, double participation);  // validated
  /// From the stiffness ratio k_i/k_1 and the frequency ratio ω_i/ω_1 (β_i = (ω_i/ω_1)²/(k_i/k_1)).
  static Eigenmode from_ratios(const Cantilever& first, double frequency_ratio, double stiffness_ratio,
                               double quality_factor, double participation);
};

/// λ_i of the clamped-free Euler–Bernoulli beam (1 + cos λ cosh λ = 0), i = 1..3.
double euler_bernoulli_eigenvalue(int mode);
/// γ_i = (−1)^{i+1} 4σ_i/λ_i, σ_i = (cosh λ_i + cos λ_i)/(sinh λ_i + sin λ_i): the participation of the
/// tip-normalised mode i in a base motion (∫φ_i / ∫φ_i² with φ_i(tip) = 1).
double euler_bernoulli_participation(int mode);
/// The first `count` (1..3) modes of a uniform rectangular cantilever whose first mode is `first`: frequencies
/// and stiffnesses from λ_i (header), β_i = 1; Q_i from `quality_factors` (one per higher mode) or, when empty,
/// Q_1 ω_i/ω_1 (the same viscous damping coefficient per unit mass on every mode).
std::vector<Eigenmode> euler_bernoulli_modes(const Cantilever& first, int count,
                                             const std::vector<double>& quality_factors = {});

enum class Excitation { direct, base };
const char* excitation_name(Excitation excitation);

/// Low-Q operation in a liquid: every mode carries the added mass μ m_i (the fluid moving with the beam) and a
/// fluid damping coefficient per unit (vacuum) mass c_f, the same on every mode, set by the quality factor Q_f
/// that the fluid damping alone gives the first mode in the liquid:
///   ω_i' = ω_i/√(1 + μ),   1/Q_i' = 1/(Q_i √(1 + μ)) + (ω_1'/ω_i')/Q_f,   forces divided by 1 + μ.
struct Medium {
  double added_mass_ratio = 0.0;                                        // μ ≥ 0
  double fluid_quality_factor = std::numeric_limits<double>::infinity();  // Q_f > 0 (∞: no fluid damping)
  void validate() const;
  bool vacuum() const {
    return added_mass_ratio == 0.0 && fluid_quality_factor == std::numeric_limits<double>::infinity();
  }
};

/// The multi-mode cantilever, its excitation at one or two frequencies, the law and the separation.
struct MultiModeModel {
  std::vector<Eigenmode> modes;  // 1..3, the fundamental first (β_1 = 1)
  /// 1 or 2 drives. Direct: amplitude Γ_d = force at the tip per unit mode-1 mass; base: the base displacement
  /// amplitude Y_d (length). Frequencies ω_d (rad per time unit).
  std::vector<Drive> drives;
  Excitation excitation = Excitation::direct;
  Medium medium;
  impact::ForceLaw law;
  double separation;

  MultiModeModel(std::vector<Eigenmode> modes, std::vector<Drive> drives, Excitation excitation, Medium medium,
                 impact::ForceLaw law, double separation);  // validated
  /// The single-mode model of the same cantilever: mode 1 and drive 1 only, direct excitation in vacuum.
  static MultiModeModel from_single(const TappingModel& model);

  int mode_count() const { return static_cast<int>(modes.size()); }
  int drive_count() const { return static_cast<int>(drives.size()); }
  /// Whether this is exactly a TappingModel (one mode, one direct drive, vacuum): it is then simulated by the
  /// single-mode system, to the last bit.
  bool single_mode() const;
  /// The TappingModel of mode 1 with drive 1 (the medium applied; the tip force scaled by ρ).
  TappingModel first_mode() const;
  MultiModeModel with_separation(double l) const;

  // The effective (medium-applied) coefficients of the equations of the header.
  double frequency(int i) const;        // ω_i'
  double quality_factor(int i) const;   // Q_i'
  double damping(int i) const { return frequency(i) / quality_factor(i); }  // 2ξ_i'ω_i'
  double force_factor() const { return 1.0 / (1.0 + medium.added_mass_ratio); }  // ρ
  double coupling(int i) const { return force_factor() * modes[i].mass_ratio; }  // ρβ_i: the tip force on mode i
  /// Amplitude of the modal forcing of mode i by drive d (ρβ_iΓ_d direct, ργ_iω_d²Y_d base).
  double forcing(int i, int d) const;
  /// Base displacement amplitude of drive d (0 for direct excitation).
  double base_amplitude(int d) const { return excitation == Excitation::base ? drives[d].amplitude : 0.0; }
  /// Transfer of mode i: 1/(s² + 2ξ_i'ω_i' s + ω_i'²).
  std::complex<double> transfer(int i, std::complex<double> s) const;
  /// Free (no tip force) steady-state complex amplitude of mode i at drive d: q_i = Re(c e^{iω_d t}).
  std::complex<double> free_response(int i, int d) const;
  /// Free steady-state complex amplitude of the tip x (base motion included) at drive d.
  std::complex<double> free_tip_response(int d) const;
  /// Shortest natural period of the modes (2π/ω_max').
  double shortest_mode_period() const;
};

/// The drive amplitude (Γ or Y) at frequency ω that makes mode i's free amplitude `amplitude` under `excitation`
/// (|forcing| · |L_i(iω)| = amplitude). Needs the other fields of a model: modes, excitation, medium.
double drive_for_mode_amplitude(const std::vector<Eigenmode>& modes, Excitation excitation, const Medium& medium,
                                int mode, double frequency, double amplitude);

}  // namespace afmkit::tapping
