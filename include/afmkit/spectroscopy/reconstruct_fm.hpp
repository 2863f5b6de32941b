#pragma once
// FM-AFM force reconstruction (docs/reconstruction.md): the frequency shift Δf(z) measured at constant oscillation
// amplitude A → the tip–sample force F(z), by the Sader–Jarvis formula (Sader & Jarvis, APL 84, 1801 (2004)) or the
// matrix method (Giessibl, APL 78, 123 (2001)), then the round trip: the reconstructed force, as the table law
// written, run back through the forward model and compared with the measured Δf.
//
// SI units: z [m] = the closest tip–sample distance of the oscillation, Δf [Hz], A [m], k [N/m], f0 [Hz], F [N]
// (positive repulsive, docs/conventions.md), U [J]. The forward model of the round trip (FmOptions: exact_round_trip) is
// either afmkit's exact FM orbits of the reconstructed table law (tapping/fm.hpp: the default) or the first-order
// large-amplitude formula Δf(z) = −(f0/(π k A)) ∫_{−1}^{1} F(z + A(1 + u)) u/√(1 − u²) du by quadrature.
#include <cstdint>
#include <string>
#include <vector>

#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/spectroscopy/reconstruct_kernels.hpp"

namespace afmkit::spectroscopy {

enum class FmMethod { sader_jarvis, matrix };
/// Δf beyond the last measured point: zero (the default: the integrals end there, the law is 0 beyond) or
/// exponential (fitted to the last points and continued analytically).
enum class TailModel { zero, exponential };
const char* to_string(FmMethod method);
const char* to_string(TailModel tail);
FmMethod fm_method_from(const std::string& name);  // InvalidParameter("method", …)
TailModel tail_model_from(const std::string& name);  // InvalidParameter("tail", …)

struct FmSettings {
  double spring_constant;      ///< k [N/m] > 0
  double resonance_frequency;  ///< f0 [Hz] > 0
  double amplitude;            ///< A [m] > 0 (oscillation amplitude, half peak-to-peak)
  FmSettings(double spring_constant, double resonance_frequency, double amplitude);  // validated
};

struct FmOptions {
  FmMethod method = FmMethod::sader_jarvis;
  TailModel tail = TailModel::zero;
  int noise_realisations = 8;  ///< noise propagated by this many synthetic realisations (0: none)
  std::uint64_t seed = 1;      ///< of those realisations
  bool round_trip = true;
  /// The round trip's forward model: the exact FM orbits of afmkit tapping fm (self-excited cantilever, ideal
  /// loops, at the measured closest distances), or Giessibl's first-order large-amplitude formula by quadrature.
  bool exact_round_trip = true;
  /// Exact round trip: at this many of the measured distances, evenly spread (0: all of them).
  int round_trip_points = 40;
  /// Exact round trip: the cantilever's quality factor (Δf hardly depends on it when Q ≫ 1).
  double quality_factor = 1e4;
};

/// The measured curve (any distance order; strictly monotone, finite, ≥ 5 points).
struct FmCurve {
  std::vector<double> distance;         ///< z [m]
  std::vector<double> frequency_shift;  ///< Δf [Hz]
};

struct FmReconstruction {
  std::string method;
  std::vector<double> distance;          ///< z [m], ascending
  std::vector<double> frequency_shift;   ///< Δf [Hz] as measured (ascending z)
  std::vector<double> force;             ///< F [N]
  std::vector<double> energy;            ///< U(z) = ∫_z^∞ F dt [J]
  std::vector<double> force_uncertainty; ///< 1σ of F from the noise estimated in Δf [N] (0 without noise)
  std::vector<double> round_trip_frequency_shift;  ///< Δf of the table law by the forward model [Hz] (NaN: none)
  std::vector<double> residual;          ///< round trip − measured [Hz]
  double residual_rms = 0.0;             ///< [Hz]
  double residual_max = 0.0;             ///< [Hz]
  double noise = 0.0;                    ///< estimated white noise of Δf [Hz]
  double interaction_length = 0.0;       ///< where |Δf| falls to 1/e of its largest value, from it [m]
  ExponentialTail tail;                  ///< the tail used (of Ω = Δf/f0)
  double tail_sensitivity = 0.0;         ///< max |F(exponential tail) − F(zero tail)| [N] (NaN: no tail fit)
  impact::ForceCurve law;                ///< the table law (nm, nN), both branches F
  int round_trip_orbits = 0;         ///< exact round trip: FM orbits found (0: first-order round trip)
  long round_trip_simulations = 0;   ///< exact round trip: one-period simulations of their Newton solves
  std::string round_trip_model;
  std::vector<std::string> notes;        ///< ill-posedness and what was assumed
};

/// Validates the curve (InvalidParameter naming distance / frequency_shift and the index) and reconstructs.
FmReconstruction reconstruct_fm(const FmCurve& curve, const FmSettings& settings, const FmOptions& options = {});

/// The closed-form first-order Δf of an exponential force F = −F0 e^{−z/λ} (tests, docs):
///   Δf(z) = −(f0 F0 / (k A)) e^{−(z + A)/λ} I_1(A/λ).
double exponential_force_frequency_shift(double z, double f0_force, double decay_length, const FmSettings& s);
/// The closed-form first-order Δf of the van der Waals sphere–plane force F = −C/z² (C = A_H R/6):
///   Δf(z) = −f0 C / (k (z (z + 2A))^{3/2}).
double inverse_square_force_frequency_shift(double z, double c, const FmSettings& s);

}  // namespace afmkit::spectroscopy
