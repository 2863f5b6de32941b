// `spectroscopy fit` of an AM-AFM amplitude/phase curve: its residuals and outputs around the shared least-squares
// engine (fit_engine.hpp; docs/fitting.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/numbers.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"
#include "afmkit/tapping/cantilever_limits.hpp"
#include "fit_engine.hpp"

namespace afmkit::spectroscopy {

namespace {

using afmkit::numbers::nan;

/// The data in the sweep's order.
FitCurve sorted_curve(const FitCurve& c, const std::vector<std::size_t>& order) {
  FitCurve s;
  s.distance = engine::in_order(c.distance, order);
  s.amplitude = engine::in_order(c.amplitude, order);
  s.phase = engine::in_order(c.phase, order);
  return s;
}

/// The model oscillates with the true free amplitude free_amplitude × amplitude_scale (AmForwardModel::model): at
/// the values a fit starts from (or a prediction uses) it must lie in the cantilever's range, else the user's
/// amplitude_scale is refused here (exit 2) rather than the forward model failing at its first evaluation. A trial
/// value out of range during the fit is a failed step, as any other.
void check_true_amplitude(const FitSettings& settings, const ModelValues& values) {
  using tapping::CantileverSetting;
  const double a = settings.free_amplitude * values.amplitude_scale;
  const double upper = tapping::cantilever_limit(CantileverSetting::amplitude).upper;
  if (a > 0.0 && a <= upper) return;  // false for NaN
  throw InvalidParameter("amplitude_scale",
                         fmt::format("amplitude_scale = {} with free_amplitude = {:.6g} m makes the true free "
                                     "amplitude {:.6g} m, out of range: it must be > 0 and <= {:g} m",
                                     values.amplitude_scale, settings.free_amplitude, a, upper));
}

}  // namespace

AmPrediction predict_am_curve(const std::vector<double>& distance, const FitSettings& settings,
                              const FitOptions& options) {
  settings.validate();
  FitCurve c;
  c.distance = distance;
  c.amplitude.assign(distance.size(), 1.0);
  c.validate();
  const std::vector<std::size_t> order = engine::sweep_order(distance, options.direction);
  const AmForwardModel model(settings, options, engine::in_order(distance, order));
  const ModelValues v = ModelValues::of(options);
  check_true_amplitude(settings, v);
  const CurveEvaluation e = model.walk(v);
  if (!e.ok) throw NumericalFailure("forward model: " + e.error);
  AmPrediction out;
  out.amplitude.resize(distance.size());
  out.phase.resize(distance.size());
  out.contact.resize(distance.size());
  out.jumped.resize(distance.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    out.amplitude[i] = e.amplitude[k] / v.amplitude_scale;
    out.phase[i] = engine::wrap(e.phase[k] + v.phase_offset);
    out.contact[i] = e.contact[k];
    out.jumped[i] = e.jumped[k];
  }
  return out;
}

FitResult fit_am_curve(const FitCurve& curve, const FitSettings& settings, const FitOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  curve.validate();
  settings.validate();
  options.validate();
  FitResult r;
  r.mode = FitMode::am;
  r.parameters = fit_parameter_info(options, FitMode::am);
  check_true_amplitude(settings, ModelValues::of(options));
  const FitCurve data = sorted_curve(curve, engine::sweep_order(curve.distance, options.direction));
  const std::size_t n = data.distance.size();
  const bool phase = !data.phase.empty();
  const long p = static_cast<long>(r.parameters.size());
  const long m = static_cast<long>(n) * (phase ? 2 : 1);
  if (m <= p)
    throw InvalidParameter("parameters", fmt::format("{} parameters cannot be fitted to {} residuals: fewer "
                                                     "parameters or more points",
                                                     p, m));
  // weights: the given noise, else the data's scatter (floored: noise-free synthetic data)
  std::vector<double> a_norm(data.amplitude);
  for (double& a : a_norm) a /= settings.free_amplitude;
  r.amplitude_noise = engine::noise(options.amplitude_noise, a_norm, false, 1e-9, r.noise_estimated_amplitude);
  r.phase_noise = phase ? engine::noise(options.phase_noise, data.phase, true, 1e-9, r.noise_estimated_phase) : nan;
  const double sigma_a = r.amplitude_noise, sigma_p = phase ? r.phase_noise : 1.0;
  const double a0 = settings.free_amplitude;
  // residuals (n, 2n with phase): (A_meas − A_model/s)/A0/σ_A and wrap(φ_meas − φ_model − φ0)/σ_φ
  auto raw = [&](const CurveEvaluation& e, const ModelValues& v) {
    Eigen::VectorXd res(m);
    for (std::size_t i = 0; i < n; ++i) {
      const auto k = static_cast<long>(i);
      res[k] = (data.amplitude[i] - e.amplitude[i] / v.amplitude_scale) / a0 / sigma_a;
      if (phase) res[static_cast<long>(n) + k] = engine::wrap(data.phase[i] - e.phase[i] - v.phase_offset) / sigma_p;
    }
    return res;
  };
  const AmForwardModel model(settings, options, data.distance);
  engine::Problem<AmForwardModel> problem(model, options, r.parameters, m, raw);
  const auto [e, v] = engine::solve(problem, options, r);

  r.distance = data.distance;
  r.amplitude = data.amplitude;
  r.phase = data.phase;
  double sa = 0.0, sp = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    r.fitted_amplitude.push_back(e.amplitude[k] / v.amplitude_scale);
    r.fitted_phase.push_back(engine::wrap(e.phase[k] + v.phase_offset));
    const double da = (data.amplitude[k] - r.fitted_amplitude[k]) / a0;
    sa += da * da;
    if (phase) {
      const double dp = engine::wrap(data.phase[k] - r.fitted_phase[k]);
      sp += dp * dp;
    }
  }
  r.contact = e.contact;
  r.jumped = e.jumped;
  r.rms_amplitude = std::sqrt(sa / static_cast<double>(n));
  r.rms_phase = phase ? std::sqrt(sp / static_cast<double>(n)) : nan;
  if (!std::all_of(e.periodic.begin(), e.periodic.end(), [](bool b) { return b; }))
    r.warnings.push_back("at some distances the response does not settle on a periodic orbit (one period of the "
                         "transient is compared with the data there)");
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace afmkit::spectroscopy
