#pragma once
// The forward models of `spectroscopy fit` (fit.hpp): amplitude and phase (AM) or frequency shift and dissipation
// (FM) along a measured curve from afmkit's periodic orbits, and the parameter transformations. Internal to the fit
// (its tests use it too).
#include <algorithm>
#include <atomic>
#include <map>
#include <string>
#include <vector>

#include "afmkit/core/parallel.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/tapping/fm.hpp"
#include "afmkit/tapping/sweep.hpp"

namespace afmkit::spectroscopy {

/// AM: distance_offset, amplitude_scale, phase_offset; FM: distance_offset, frequency_shift_offset.
bool is_calibration(const std::string& name, FitMode mode);
/// Any mode's calibration parameter.
bool is_calibration(const std::string& name);
/// A parameter that enters the residuals only (phase_offset, frequency_shift_offset): its Jacobian column needs no
/// orbit.
bool residual_only(const std::string& name);
/// The value of a calibration parameter in `options.initial`, else its default (0, 1, 0, 0).
double calibration_value(const FitOptions& options, const std::string& name);
/// p(u) and dp/du of the parameter's transformation (fit.hpp: Transform).
double to_parameter(const FitParameterInfo& p, double u);
double parameter_derivative(const FitParameterInfo& p, double u);

/// What each_point did: whether every point succeeded, and how many points it ran.
struct EachPointResult {
  bool all = true;
  long visited = 0;
};

/// Runs point(i) for every i < n (OpenMP threads when `parallel`) in blocks of kEachPointBlock points, stopping after
/// the block in which one returns false or throws (a warm-started evaluation: each point from the previous curve's
/// orbit there). The points run are those of the blocks up to that one: their number depends on n and on where the
/// first failure lies, never on the threads' timing, so a fit's record (orbit_evaluations) replays exactly.
inline constexpr std::size_t kEachPointBlock = 32;
template <class Point>
EachPointResult each_point(std::size_t n, bool parallel, Point&& point) {
  std::atomic<bool> failed{false};
  ExceptionCollector errors;
  std::size_t begin = 0;
  while (begin < n && !failed.load() && !errors.failed()) {
    const std::size_t end = std::min(n, begin + kEachPointBlock);
#pragma omp parallel for schedule(dynamic) if (parallel)
    for (std::size_t i = begin; i < end; ++i)
      errors.run([&] {
        if (!point(i)) failed = true;
      });
    begin = end;
  }
  return {!errors.failed() && !failed.load(), static_cast<long>(begin)};
}

/// Every value the model needs (declared below).
struct ModelValues;
/// The law of `options.law` with the values of `values.law` (SI), in the registry's physical units (nm, nN).
impact::ForceLaw build_law(const FitOptions& options, const ModelValues& values);
/// Distance in the phase plane of two states: |Δx| and |Δẋ|/ω (model units).
double state_distance(tapping::TipState a, tapping::TipState b, double omega);

/// Every value the model needs: law values (registry keys, SI) and the calibration.
struct ModelValues {
  std::map<std::string, double> law;
  double distance_offset = 0.0;  // m
  double amplitude_scale = 1.0;
  double phase_offset = 0.0;     // rad
  double frequency_shift_offset = 0.0;  // Hz
  /// The calibration of `options.initial` (or the defaults) and the law values of `options.law_values`.
  static ModelValues of(const FitOptions& options);
  /// Sets the parameter `name` (a law key or a calibration name) to p.
  void set(const std::string& name, double p);
};

/// One evaluation along the curve, in the sweep's order of the points.
struct CurveEvaluation {
  bool ok = false;
  std::string error;  // why not ok
  std::vector<tapping::PeriodicOrbit> orbits;
  std::vector<bool> periodic;
  std::vector<double> amplitude, phase;  // model amplitude [m] (not divided by s) and phase [rad] (without φ0)
  std::vector<bool> contact, jumped;
};

/// The orbits along the measured distances as an instrument sweeps them (approach from the largest distance; for
/// a retract curve, approach down to the smallest then retract).
class AmForwardModel {
 public:
  using Evaluation = CurveEvaluation;
  /// `distances` [m] in the sweep's order (approach: decreasing; retract: increasing).
  AmForwardModel(const FitSettings& settings, const FitOptions& options, std::vector<double> distances);

  /// Continuation along the curve from the free response (follow_stable_branch; a transient where a branch ends).
  CurveEvaluation walk(const ModelValues& values) const;
  /// Each point by Newton from the orbit of `from` at the same point (values close to those of `from`); falls back
  /// to walk() when a point does not converge to a stable orbit near the previous one, or when a jump of `from`
  /// moved past a point. `chord`: one chord-Newton step with the monodromy of `from` instead of Newton to the
  /// tolerance (the Jacobian's perturbed curves: off by O(step²)).
  CurveEvaluation warm(const ModelValues& values, const CurveEvaluation& from, bool chord = false) const;

  long curves() const { return curves_.load(); }
  long orbits() const { return orbits_.load(); }

 private:
  FitSettings settings_;
  FitOptions options_;
  std::vector<double> distances_;
  tapping::SweepOptions sweep_;
  mutable std::atomic<long> curves_{0}, orbits_{0};
  /// The model (law built from `values`, free amplitude s·A0) at separation 0; InvalidParameter for law values
  /// outside their ranges.
  tapping::TappingModel model(const ModelValues& values) const;
  double separation(const ModelValues& values, std::size_t i) const;  // model units (nm)
  void finish(const tapping::TappingModel& m, const ModelValues& values, CurveEvaluation& e) const;
};

/// One FM evaluation along the curve, in the sweep's order of the points.
struct FmCurveEvaluation {
  bool ok = false;
  std::string error;
  std::vector<tapping::FmOrbit> orbits;
  std::vector<tapping::FmJacobian> jacobians;  // per point, kept for the next Newton solve there (Broyden-updated)
  std::vector<double> frequency_shift, dissipation;  // model Δf [Hz] (without the offset), E [J per cycle]
  std::vector<bool> contact, jumped;
};

/// The FM orbits (tapping/fm.hpp) along the measured distances as the instrument sweeps them (approach from the
/// largest distance; retract: approach down to the smallest, then back up through the points).
class FmForwardModel {
 public:
  using Evaluation = FmCurveEvaluation;
  /// `distances` [m] in the sweep's order (approach: decreasing; retract: increasing).
  FmForwardModel(const FmFitSettings& settings, const FitOptions& options, std::vector<double> distances);

  /// Continuation along the curve from the free FM orbit (tapping::sweep_fm, through folds).
  FmCurveEvaluation walk(const ModelValues& values) const;
  /// Each point by Newton from the orbit of `from` at the same point (its Jacobian kept); falls back to walk() when
  /// a point does not converge near the previous orbit, or `from` jumped anywhere. `chord` (the Jacobian's columns)
  /// is accepted for the interface of the AM model: Newton to the tolerance from the kept Jacobian is about as cheap.
  FmCurveEvaluation warm(const ModelValues& values, const FmCurveEvaluation& from, bool chord = false) const;

  long curves() const { return curves_.load(); }
  long orbits() const { return orbits_.load(); }

 private:
  FmFitSettings settings_;
  FitOptions options_;
  std::vector<double> distances_;
  tapping::FmOptions fm_;
  mutable std::atomic<long> curves_{0}, orbits_{0};
  tapping::FmSetting setting(const ModelValues& values) const;
  double separation(const ModelValues& values, std::size_t i) const;  // model units (nm)
  void finish(FmCurveEvaluation& e) const;
};

}  // namespace afmkit::spectroscopy
