#pragma once
// Fitting a force law to a measured AM-AFM amplitude/phase-versus-distance curve, or to an FM-AFM frequency-shift
// (and dissipation) curve (docs/fitting.md; the FM fit: fit_fm_curve below and docs/fitting.md#fm-afm).
//
// Forward model: afmkit's exact periodic orbits of the tapping cantilever (seed-1 eq. 8) at the measured settings
// (k, f0, Q, A0, drive frequency), the force law built by impact::LawRegistry from the parameter values, the
// orbits continued along the curve as an instrument sweeps it (follow_stable_branch from the previous orbit,
// transients where a branch ends: the sweep engine of tapping/sweep.hpp).
//
// Calibration parameters beside the law's (all optional, fitted or fixed):
//   distance_offset d0 [m]   model separation l = distance + d0 (the measured distance is a piezo position whose
//                            zero is unknown)
//   amplitude_scale s        true amplitude = s × measured amplitude (an InvOLS error): the model runs at the free
//                            amplitude s·A0 and predicts the measured amplitude A_model / s
//   phase_offset φ0 [rad]    measured phase = model phase + φ0 (model phase: lag of x behind the drive Γ cos ωt,
//                            π/2 for the free response at resonance)
//
// Residuals (2n for n points; n without phase): (A_meas − A_model/s)/A0 / σ_A and wrap(φ_meas − φ_model − φ0) / σ_φ
// (wrap to (−π, π]); σ_A (in A/A0) and σ_φ [rad] given, or estimated from the data's scatter about a smooth curve
// (the median absolute second difference: robust to jumps).
//
// Solver: Eigen's Levenberg–Marquardt (unsupported/Eigen/NonLinearOptimization, the MINPACK lmder algorithm) in
// transformed coordinates u (bounds kept by the transformation, see FitParameterInfo), the Jacobian by forward
// differences with step fd_step in u (each perturbed orbit warm started from the current one at the same point).
// Standard errors: C = s² (JᵀJ)⁻¹ of the weighted residuals with s² = Σr²/(N − P), carried to the parameters by
// the transformation's derivative (delta method).
#include <map>
#include <string>
#include <vector>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/core/describe.hpp"
#include "afmkit/tapping/shooting.hpp"

namespace afmkit::spectroscopy {

/// A measured AM-AFM curve, SI units. Rows in any order; each row one distance.
struct FitCurve {
  std::vector<double> distance;   // [m] piezo separation / tip–sample distance up to an offset
  std::vector<double> amplitude;  // [m] first-harmonic amplitude
  std::vector<double> phase;      // [rad] phase lag (see above); empty: amplitude only
  /// Validates (InvalidParameter naming the array and the index): ≥ 3 rows, equal lengths, finite values,
  /// amplitude > 0, distinct distances.
  void validate() const;
};

/// The measured settings, SI units.
struct FitSettings {
  double spring_constant = 0.0;      // k [N/m] > 0
  double resonance_frequency = 0.0;  // f0 [Hz] > 0
  double quality_factor = 0.0;       // Q > 0
  double free_amplitude = 0.0;       // A0 [m] > 0, free amplitude at the drive frequency
  double drive_frequency = 0.0;      // [Hz] > 0 (0: at f0)
  /// InvalidParameter naming the setting: each in the range of tapping/cantilever_limits.hpp (the command line's)
  void validate() const;
};

/// A measured FM-AFM curve, SI units: the frequency shift Δf = f − f0 at constant amplitude A versus distance, and
/// optionally the energy the tip–sample force takes per cycle (from the drive signal). Rows in any order.
struct FmFitCurve {
  std::vector<double> distance;         // [m] piezo separation (model separation = distance + distance_offset)
  std::vector<double> frequency_shift;  // [Hz] Δf
  std::vector<double> dissipation;      // [J] per cycle; empty: Δf only
  /// Validates (InvalidParameter naming the array and the index): ≥ 3 rows, equal lengths, finite values, distinct
  /// distances.
  void validate() const;
};

/// The measured FM settings, SI units.
struct FmFitSettings {
  double spring_constant = 0.0;      // k [N/m] > 0
  double resonance_frequency = 0.0;  // f0 [Hz] > 0, the free resonance
  double quality_factor = 0.0;       // Q > 0
  double amplitude = 0.0;            // A [m] > 0, the oscillation amplitude the amplitude loop holds
  /// InvalidParameter naming the setting: each in the range of tapping/cantilever_limits.hpp (the command line's)
  void validate() const;
};

/// Which measurement a fit is of: AM-AFM amplitude/phase (fit_am_curve) or FM-AFM frequency shift (fit_fm_curve).
/// It decides the calibration parameters (AM: distance_offset, amplitude_scale, phase_offset; FM: distance_offset,
/// frequency_shift_offset).
enum class FitMode { am, fm };
const char* fit_mode_name(FitMode m);  // "am", "fm"

/// Which branch of the instrument sweep the data are: approach (distance decreasing) or retract (after the approach
/// down to the smallest distance).
enum class CurveDirection { approach, retract };

struct FitOptions {
  std::string law = "dmt";
  /// Law parameters (registry keys, SI units: m, Pa, N, N/m, J, J/m², Pa·s), fixed or initial values. Keys not
  /// given take the registry's defaults (or the key they follow).
  std::map<std::string, double> law_values;
  std::string force_curve;        // law = table: the force-curve file
  bool allow_energy_gain = false;
  /// The fitted parameters: law keys and/or the calibration (AM: distance_offset, amplitude_scale, phase_offset;
  /// FM: distance_offset, frequency_shift_offset).
  std::vector<std::string> parameters;
  /// Initial (or fixed) values of the calibration parameters: distance_offset [m] (0), amplitude_scale (1),
  /// phase_offset [rad] (0), frequency_shift_offset [Hz] (0); initial values of fitted law keys may be given here
  /// too (SI).
  std::map<std::string, double> initial;
  CurveDirection direction = CurveDirection::approach;
  double amplitude_noise = 0.0;  // σ_A in A/A0 (0: estimated from the data)
  /// Huber's loss beyond this many σ (docs/fitting.md#weights; 0: plain least squares).
  double huber = 5.0;
  double phase_noise = 0.0;      // σ_φ [rad] (0: estimated)
  double frequency_shift_noise = 0.0;  // FM: σ_Δf [Hz] (0: estimated)
  double dissipation_noise = 0.0;      // FM: σ_E [J] per cycle (0: estimated)
  double fd_step = 1e-3;         // forward-difference step in the transformed coordinates u
  int max_evaluations = 100;     // forward-model evaluations (curves, the Jacobian's columns included)
  double tolerance = 1e-4;       // relative reduction of the cost and relative step (LM ftol and xtol)
  /// Identifiability thresholds (docs/fitting.md#identifiability).
  double correlation_limit = 0.99;
  double condition_limit = 1e10;
  double flat_column = 1e-3;  // a parameter whose weighted Jacobian column is shorter is flat (not identifiable)
  /// Accuracy of the orbits: the integrator's relative tolerance and the shooting tolerance (the tolerance of
  /// tapping::ShootingOptions, declared by its describe_tolerance(); the sweep's defaults are 1e-10 and 1e-11: a fit
  /// to data with noise ~1e-3 needs less).
  double integrator_tolerance = 1e-9;
  double shooting_tolerance = 1e-10;
  bool parallel = true;          // the orbits of a warm-started evaluation in parallel (OpenMP)
  Cancellation cancellation;

  /// The solver's settings, declared once (core/describe.hpp): key, help, unit, range; the defaults are the
  /// initializers above. `afmkit spectroscopy fit` lists them in this order.
  template <class Archive, class Self>
  static void describe(Archive& a, Self& o) {
    a.real("huber", o.huber,
           "Huber's loss beyond this many σ: a point far off (another branch next to a jump) pulls linearly; 0: plain "
           "least squares",
           "dimensionless", Range::non_negative());
    a.real("fd_step", o.fd_step, "forward-difference step of the Jacobian in the transformed parameters",
           "dimensionless", Range::closed(1e-8, 0.1));
    a.integer("max_evaluations", o.max_evaluations,
              "budget of forward-model evaluations (curves, Jacobian columns included)", 2, 1000000);
    a.real("tolerance", o.tolerance,
           "Levenberg–Marquardt ftol and xtol (relative reduction of the cost, relative step)", "dimensionless",
           Range::closed(1e-15, 0.1));
    a.real("integrator_tolerance", o.integrator_tolerance, "relative tolerance of the orbits' integrator",
           "dimensionless", Range::closed(1e-14, 1e-4));
    tapping::ShootingOptions::describe_tolerance(a, o.shooting_tolerance, "tolerance of the orbits' Newton shooting",
                                                 Range::closed(1e-14, 1e-4));
    a.real("correlation_limit", o.correlation_limit, "warn when |correlation| of two parameters exceeds this",
           "dimensionless", Range::open(0.0, 1.0));
    a.real("condition_limit", o.condition_limit, "warn when the condition number of the scaled JᵀWJ exceeds this",
           "dimensionless", Range{1.0, 1e300, true, false});
    a.real("flat_column", o.flat_column,
           "a parameter whose weighted Jacobian column is shorter is flat (not identifiable)", "dimensionless",
           Range::closed(0.0, 1.0));
  }
  void validate() const;  // InvalidParameter naming the key (the ranges of describe() and the noises >= 0)
};

/// How a parameter is kept in its valid range: p(u) with u the solver's coordinate.
enum class Transform {
  identity,  // p = p0 + u·scale              (unbounded: distance_offset, scale 1 nm; phase_offset, 1 rad)
  log,       // p = lower + (p0 − lower)·e^u  (lower bound only: every registry key has lower 0)
  logistic   // p = lower + (upper − lower)/(1 + e^−(u + u0))  (both bounds)
};
const char* transform_name(Transform t);  // "identity", "log", "logistic"

struct FitParameterInfo {
  std::string name;
  std::string unit;  // SI unit ("m", "Pa", "J", "rad", "dimensionless", ...)
  double initial = 0.0;
  double lower = 0.0, upper = 0.0;  // valid range (±inf when open-ended)
  Transform transform = Transform::identity;
  double scale = 1.0;  // identity: the size of u = 1 in the parameter's unit
};

/// Status of a fit (docs/fitting.md#status): ok when the solver stopped on one of its tolerances.
enum class FitStatus { ok, not_converged, failed };
const char* fit_status_name(FitStatus s);  // "ok", "not_converged", "failed"

struct FitResult {
  FitMode mode = FitMode::am;
  FitStatus status = FitStatus::failed;
  std::string solver_status;  // Eigen's LevenbergMarquardtSpace::Status in words
  std::vector<FitParameterInfo> parameters;
  std::vector<double> estimates;          // SI
  std::vector<double> standard_errors;    // SI (inf: not identifiable)
  std::vector<std::vector<double>> correlation;  // P×P (NaN where a parameter is not identifiable)
  std::vector<std::string> warnings;      // identifiability and model warnings, in words
  std::vector<bool> identifiable;         // per parameter
  double condition_number = 0.0;          // of the scaled JᵀJ (unit diagonal)
  // the data (sorted by the sweep's order) and the fit
  std::vector<double> distance, amplitude, phase;             // measured, SI (phase empty when not given)
  std::vector<double> fitted_amplitude, fitted_phase;         // model at the estimates, as measured (÷s, +φ0)
  // FM (mode fm; the AM arrays above are then empty): measured and fitted (model + frequency_shift_offset)
  std::vector<double> frequency_shift, fitted_frequency_shift;  // [Hz]
  std::vector<double> dissipation, fitted_dissipation;          // [J] per cycle (empty when not measured)
  std::vector<bool> contact;                                  // orbit reaches the law's contact gap
  std::vector<bool> jumped;                                   // the response jumped onto another branch there
  double amplitude_noise = 0.0, phase_noise = 0.0;            // σ used (A/A0, rad)
  bool noise_estimated_amplitude = false, noise_estimated_phase = false;
  double rms_amplitude = 0.0;   // RMS of (A_meas − A_fit)/A0
  double rms_phase = 0.0;       // RMS of the phase residual [rad]
  double frequency_shift_noise = 0.0, dissipation_noise = 0.0;  // FM: σ used [Hz], [J]
  bool noise_estimated_frequency_shift = false, noise_estimated_dissipation = false;
  double rms_frequency_shift = 0.0;  // FM: RMS of Δf_meas − Δf_fit [Hz]
  double rms_dissipation = 0.0;      // FM: RMS of E_meas − E_fit [J] (NaN without dissipation)
  double cost = 0.0;            // Σ r² (weighted) at the estimates
  double reduced_chi2 = 0.0;    // Σ r² / (N − P)
  long curve_evaluations = 0;   // forward-model evaluations (whole curves, Jacobian columns included)
  long orbit_evaluations = 0;   // periodic orbits computed (every point of every evaluation)
  long failed_evaluations = 0;  // trial points where the model could not be evaluated (rejected steps)
  int iterations = 0;
  double seconds = 0.0;
  /// Every law value used (registry keys, SI), fitted ones at their estimates.
  std::map<std::string, double> law_values;
};

/// The information of every parameter name the fit knows for `options.law` (transform, range, SI unit, initial).
/// InvalidParameter("parameters", …) for an unknown name or one the law does not read; ("initial"/law key) for an
/// initial value outside the range or 0 on a log scale.
/// `mode` decides the calibration parameters.
std::vector<FitParameterInfo> fit_parameter_info(const FitOptions& options, FitMode mode = FitMode::am);

/// Weighted nonlinear least squares (see above). Bad input -> InvalidParameter; the model failing at the initial
/// values -> NumericalFailure; a fit that stops on its budget -> status not_converged (the result still holds
/// everything at the best point found).
FitResult fit_am_curve(const FitCurve& curve, const FitSettings& settings, const FitOptions& options);

/// The forward model alone: amplitude [m] and phase [rad] at each distance of `distance` (in the order given),
/// for the law and calibration values of `options` (law_values + initial; parameters ignored). Synthetic data and
/// checks. `orbits`: if given, receives the number of orbits computed.
struct AmPrediction {
  std::vector<double> amplitude, phase;
  std::vector<bool> contact, jumped;
};
AmPrediction predict_am_curve(const std::vector<double>& distance, const FitSettings& settings,
                              const FitOptions& options);

/// The FM fit (docs/fitting.md#fm-afm). Forward model: the exact FM orbits of `tapping fm` (tapping/fm.hpp: the
/// self-excited cantilever at constant amplitude A with an ideal phase-locked loop) at model separation
/// l = distance + distance_offset, continued along the curve as the approach (or retract) sweeps it; a new trial
/// point starts each orbit by Newton from the orbit at the same point of the best evaluation so far. Residuals (n,
/// or 2n with dissipation): (Δf_meas − Δf_model − Δf_off)/σ_Δf and (E_meas − E_model)/σ_E, through Huber's loss;
/// σ given or estimated from the data's scatter as in the AM fit. Solver, transforms, statistics and status: as
/// fit_am_curve.
FitResult fit_fm_curve(const FmFitCurve& curve, const FmFitSettings& settings, const FitOptions& options);

/// The FM forward model alone: frequency shift [Hz] (+ frequency_shift_offset of `options.initial`) and dissipation
/// [J per cycle] at each distance (in the order given). NumericalFailure where no FM orbit is found.
struct FmPrediction {
  std::vector<double> frequency_shift, dissipation;
  std::vector<bool> contact, jumped;
};
FmPrediction predict_fm_curve(const std::vector<double>& distance, const FmFitSettings& settings,
                              const FitOptions& options);

/// Factor converting a registry law unit to SI ("nm" -> 1e-9, "GPa" -> 1e9, "nN" -> 1e-9, others 1) and the SI
/// unit's name ("m", "Pa", "N", ...).
double law_unit_to_si(const std::string& unit);
std::string law_si_unit(const std::string& unit);

}  // namespace afmkit::spectroscopy
