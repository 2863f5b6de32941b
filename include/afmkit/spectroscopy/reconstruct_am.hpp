#pragma once
// AM-AFM force reconstruction (docs/reconstruction.md#am): amplitude A(l) and phase φ(l) measured against the
// separation l at free amplitude A0, Q, k, f0 and drive frequency f → the conservative force F(D) at the lower
// turning point D = l − A, the energy dissipated per cycle E_dis, and a table law whose branches differ by the
// dissipation; then the round trip: the law run through afmkit's exact orbits (tapping sweep, approach) at the
// measured settings, A/A0 and φ compared with the measurement.
//
// Phase: afmkit's convention (docs/conventions.md): x ≈ offset + A cos(ωt − φ) for the drive cos ωt, φ the lag of
// the response, in (0, π); φ = π/2 for the free cantilever driven at resonance.
// SI units: l, A, A0, D [m]; f0, f [Hz]; φ [rad]; k [N/m]; F [N]; E_dis [J].
#include <string>
#include <vector>

#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/spectroscopy/reconstruct_fm.hpp"

namespace afmkit::spectroscopy {

/// katan: Katan, van Es & Oosterkamp, Nanotechnology 20, 165703 (2009); payam: Payam, Martín-Jiménez & García,
/// Nanotechnology 26, 185706 (2015); hoelscher: Hölscher, APL 89, 123109 (2006). The equations: the docs.
enum class AmMethod { katan, payam, hoelscher };
const char* to_string(AmMethod method);
AmMethod am_method_from(const std::string& name);  // InvalidParameter("method", …)

struct AmSettings {
  double spring_constant;      ///< k [N/m] > 0
  double resonance_frequency;  ///< f0 [Hz] > 0
  double quality_factor;       ///< Q > 0
  double free_amplitude;       ///< A0 [m] > 0, at the drive frequency
  double drive_frequency;      ///< f [Hz] > 0 (f0 when built without it)
  AmSettings(double spring_constant, double resonance_frequency, double quality_factor, double free_amplitude,
             double drive_frequency = 0.0);  // validated; drive_frequency 0: f0
  double frequency_ratio() const { return drive_frequency / resonance_frequency; }
};

struct AmOptions {
  AmMethod method = AmMethod::payam;
  TailModel tail = TailModel::zero;
  bool round_trip = true;
  /// The round trip runs at this many of the measured separations, evenly spread over them (0: all of them): the
  /// exact orbits of a table law cost about 10–20 ms per separation.
  int round_trip_points = 40;
};

/// The measured curve (any separation order; strictly monotone, finite, ≥ 5 points, A > 0, φ in (0, π)).
struct AmCurve {
  std::vector<double> separation;  ///< l [m]: the cantilever's rest position above the sample (tapping sweep's)
  std::vector<double> amplitude;   ///< A [m]
  std::vector<double> phase;       ///< φ [rad]
};

struct AmReconstruction {
  std::string method;
  // the measurement, ascending in l
  std::vector<double> separation, amplitude, phase;
  std::vector<double> dissipation;  ///< E_dis [J] per point (Cleveland et al. 1998, exact first harmonic)
  // the points used (D strictly increasing with l), ascending in D
  std::vector<double> gap;             ///< D = l − A [m]
  std::vector<double> omega;           ///< the equivalent Ω = Δf/f0 the method inverts (katan: √(1 + 2 Ω_eq) − 1)
  std::vector<double> force;           ///< conservative F(D) [N]
  std::vector<double> force_uncertainty;  ///< 1σ of F from the noise estimated in Ω_eq (8 realisations) [N]
  std::vector<double> gap_dissipation; ///< E_dis at those points [J] (monotone fit, 0 above the contact part)
  std::vector<double> approach_force;  ///< F + ΔF/2 [N]
  std::vector<double> retract_force;   ///< F − ΔF/2 [N]
  std::size_t dropped = 0;             ///< points left out because D = l − A did not increase with l
  double contact_gap = 0.0;            ///< the largest D where the branches differ [m] (NaN: nowhere)
  impact::ForceCurve law;              ///< the table law (nm, nN)
  // the round trip at every measured separation (approach sweep of the law)
  std::vector<double> round_trip_amplitude_ratio, round_trip_phase;
  std::vector<double> residual_amplitude_ratio, residual_phase;  ///< round trip − measured (A/A0; rad)
  double rms_amplitude_ratio = 0.0, rms_phase = 0.0;              ///< (NaN without a round trip)
  int round_trip_orbits = 0;  ///< periodic orbits the round trip found (one per separation it reached)
  std::string round_trip_model;
  std::vector<std::string> notes;
};

/// E_dis = π k A (A0 |1 − r² + i r/Q| sin φ − A r/Q), r = f/f0 (the first-harmonic energy balance; at r = 1 the
/// formula of Cleveland et al., APL 72, 2613 (1998): (π k A²/Q)((A0/A) sin φ − 1)); off resonance Anczykowski's
/// (π k A²/Q)((A0'/A) sin φ − r) with A0' = Q A0 |1 − r² + i r/Q|, the free amplitude at resonance.
double dissipated_energy(double amplitude, double phase, const AmSettings& s);
/// Ω_eq = −(1 − r²)/2 + (A0/(2A)) |1 − r² + i r/Q| cos φ (at r = 1: A0 cos φ/(2 Q A)).
double equivalent_frequency_shift(double amplitude, double phase, const AmSettings& s);

/// Validates (InvalidParameter naming separation / amplitude / phase and the index) and reconstructs.
AmReconstruction reconstruct_am(const AmCurve& curve, const AmSettings& settings, const AmOptions& options = {});

/// The departure branch from the dissipation: E_dis(D) (D ascending) → ΔF(D) = −dE/dD of its non-increasing
/// least-squares fit, 0 above the largest D where that fit exceeds `threshold` [J]; returns ΔF [N] per point and
/// sets `contact_gap` (NaN when no point exceeds the threshold).
std::vector<double> branch_difference(const std::vector<double>& gap, const std::vector<double>& dissipation,
                                      double threshold, double& contact_gap);

}  // namespace afmkit::spectroscopy
