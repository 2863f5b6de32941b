#pragma once
// A RealtimeFilter design exported for the freestanding C core (afmkit/embed/afmkit_embed.h, docs/embedding.md).
//
//   embed::ExportSpec s;  s.sample_rate = 20000; s.rotation_frequency = 2π·50; s.harmonics = 10; …
//   embed::ExportedDesign d(s);      // validated and checked, else InvalidParameter naming the parameter
//   d.circle_coefficients() …        // the arrays of afmkit_embed_coefficients, already rounded to the precision
//
// The ZeroOrderHold RealtimeFilter's modal recursion (RealtimeFilter::modal_coefficients) is carried over:
//   damped pairs: (c, s, g1, g2, w1, w2, e1, e2) as they are (coupled form);
//   undamped pairs (the rejected oscillators' exact modes ±ikΩ): magic-circle coordinates y = S q,
//     S = [[1, 0], [ε/2, cos(φ/2)]], ε = 2 sin(φ/2), φ the rotation angle per sample of the modal pair (signed,
//     q ← R(φ) q); with the ROUNDED ε the homogeneous map [[1, −ε], [ε, 1 − ε²]] has determinant 1 and its
//     eigenvalues e^{±iφ'} (2 sin(φ'/2) = ε) exactly on the unit circle; cos(φ'/2) = √(1 − ε²/4) is used in S so
//     that S is exact for the map the target runs. Input a = (S g)_1, b = (S g)_2 − ε a; weights w S⁻¹, e S⁻¹;
//   real modes: (r, g, w, e).
// Checks (each throws InvalidParameter naming the parameter, the reason and the allowed range):
//   (a) closed-loop stability with the declared plant (γ) and delay τ plus one sample (the sampled controller's
//       latency): spectral abscissa < 0 (control_spectra, as `afmkit control roots`) — "delay" if the undelayed
//       loop is stable, else "alpha";
//   (b) footprint (coefficients + state + handle, exact sizeof of the C structs) ≤ target_memory — "harmonics";
//   (c) Nyquist: N Ω < π f_s (RealtimeFilter's own check) — "sample_rate";
//   (d) float only: every damped mode's per-sample decay 1 − |e^{λh}| (of the rounded coefficients) must be
//       ≥ kFloatDecayUlps · 2⁻²⁴ (64 float ulps of 1 below 1), so that rounding (≈ 1 ulp per coefficient, a few per
//       update) changes the decay rate by a few per cent at most and can never make a mode unstable —
//       "sample_rate" (hint: lower f_s / decimate, or precision double).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/plant.hpp"

namespace afmkit::embed {

enum class Precision { Float, Double };
const char* to_string(Precision precision);  ///< "float" | "double"
/// "float" or "double"; InvalidParameter(parameter, …) otherwise.
Precision precision_from(std::string_view name, const std::string& parameter = "precision");

/// Exact memory of one filter on the target (sizeof of the C types in the precision), bytes.
struct CoreFootprint {
  std::size_t coefficient_struct = 0;  // sizeof(afmkit_embed_coefficients)
  std::size_t coefficient_arrays = 0;  // the pair / circle / real arrays
  std::size_t state = 0;               // the caller's state array
  std::size_t filter_struct = 0;       // sizeof(afmkit_embed_filter)
  std::size_t total() const { return coefficient_struct + coefficient_arrays + state + filter_struct; }
};
/// Footprint of a core with these mode counts.
CoreFootprint footprint_for(Precision precision, int pairs, int circles, int reals);

inline constexpr double kFloatDecayUlps = 64.0;  // (d): smallest damped decay 1 − |e^{λh}| in units of 2⁻²⁴
inline constexpr double kDefaultInputLimitFloat = 1e15;    // largest accepted |m| (float core)
inline constexpr double kDefaultInputLimitDouble = 1e150;  // as RealtimeFilter::kDefaultInputLimit
inline constexpr int kMaxHarmonics = 1000;                 // the stability check is O(N²) (control_spectra)

/// What the design is made for, in the library's units.
struct ExportSpec {
  double sample_rate = 0.0;         // f_s [samples/s]
  double rotation_frequency = 0.0;  // Ω [rad/s]
  int harmonics = 10;               // N (eq. 15)
  double alpha = 0.0, beta = 0.0;   // couplings (20) [rad/s]: a0 = α, a_k = 2α, b_k = −2β/k
  double gain = 0.0;                // K [rad/s]
  std::vector<int> rejected{1};     // rejected harmonics
  control::PlantKind plant = control::PlantKind::Static;
  double plant_rate = 0.0;          // γ [rad/s]
  double delay = 0.0;               // τ [s]
  Precision precision = Precision::Float;
  double input_limit = 0.0;         // largest accepted |m| [signal]; 0: the precision's default
  std::size_t target_memory = 0;    // bytes available for one filter; 0: no limit

  /// InvalidParameter naming the parameter and its range: f_s, Ω, K, γ > 0 finite; α, β finite; τ ≥ 0 finite;
  /// N in [1, kMaxHarmonics]; rejected non-empty, in [1, N], no repeats; input_limit 0 or in (0, 1e30] (float) /
  /// (0, 1e150] (double).
  void validate() const;
  double resolved_input_limit() const;
  control::OscillatorBank bank() const;  // OscillatorBank::with_couplings(Ω, N, α, β, K, rejected)
};

class ExportedDesign {
 public:
  /// Builds and checks (a)–(d) above; InvalidParameter on failure.
  explicit ExportedDesign(const ExportSpec& spec);

  const ExportSpec& spec() const& { return spec_; }
  int pairs() const { return static_cast<int>(pair_.size() / 8); }      // damped pairs
  int circles() const { return static_cast<int>(circle_.size() / 7); }  // undamped (magic-circle) pairs
  int reals() const { return static_cast<int>(real_.size() / 4); }
  /// Coefficient arrays in the C layout (AFMKIT_EMBED_*_STRIDE), values exactly representable in the precision.
  const std::vector<double>& pair_coefficients() const& { return pair_; }
  const std::vector<double>& circle_coefficients() const& { return circle_; }
  const std::vector<double>& real_coefficients() const& { return real_; }
  std::vector<int> circle_harmonics() const { return circle_k_; }  // k of each undamped pair
  double input_limit() const { return input_limit_; }              // rounded to the precision
  std::size_t state_size() const { return static_cast<std::size_t>(2 * (pairs() + circles()) + reals()); }
  CoreFootprint footprint() const { return footprint_for(spec_.precision, pairs(), circles(), reals()); }
  double spectral_abscissa() const { return abscissa_; }  // [1/s], of the loop checked in (a)
  double smallest_decay() const { return smallest_decay_; }  // min 1 − |e^{λh}| over damped modes (rounded coeffs)

 private:
  ExportSpec spec_;
  std::vector<double> pair_, circle_, real_;
  std::vector<int> circle_k_;
  double input_limit_ = 0.0, abscissa_ = 0.0, smallest_decay_ = 1.0;
};

}  // namespace afmkit::embed
