// `spectroscopy fit` of an FM-AFM frequency-shift (and dissipation) curve: its residuals and outputs around the
// shared least-squares engine (fit_engine.hpp; docs/fitting.md#fm-afm).
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/numbers.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"
#include "fit_engine.hpp"

namespace afmkit::spectroscopy {

namespace {

using afmkit::numbers::nan;

double rms(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(s / static_cast<double>(a.size()));
}

}  // namespace

FmPrediction predict_fm_curve(const std::vector<double>& distance, const FmFitSettings& settings,
                              const FitOptions& options) {
  settings.validate();
  FmFitCurve c;
  c.distance = distance;
  c.frequency_shift.assign(distance.size(), 0.0);
  c.validate();
  const std::vector<std::size_t> order = engine::sweep_order(distance, options.direction);
  const FmForwardModel model(settings, options, engine::in_order(distance, order));
  const ModelValues v = ModelValues::of(options);
  const FmCurveEvaluation e = model.walk(v);
  if (!e.ok) throw NumericalFailure("FM forward model: " + e.error);
  FmPrediction out;
  out.frequency_shift.resize(distance.size());
  out.dissipation.resize(distance.size());
  out.contact.resize(distance.size());
  out.jumped.resize(distance.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    out.frequency_shift[i] = e.frequency_shift[k] + v.frequency_shift_offset;
    out.dissipation[i] = e.dissipation[k];
    out.contact[i] = e.contact[k];
    out.jumped[i] = e.jumped[k];
  }
  return out;
}

FitResult fit_fm_curve(const FmFitCurve& curve, const FmFitSettings& settings, const FitOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  curve.validate();
  settings.validate();
  options.validate();
  FitResult r;
  r.mode = FitMode::fm;
  r.parameters = fit_parameter_info(options, FitMode::fm);
  const std::vector<std::size_t> order = engine::sweep_order(curve.distance, options.direction);
  const std::vector<double> distance = engine::in_order(curve.distance, order);
  const std::vector<double> df = engine::in_order(curve.frequency_shift, order);
  const std::vector<double> diss = engine::in_order(curve.dissipation, order);
  const std::size_t n = distance.size();
  const bool with_e = !diss.empty();
  const long p = static_cast<long>(r.parameters.size());
  const long m = static_cast<long>(n) * (with_e ? 2 : 1);
  if (m <= p)
    throw InvalidParameter("parameters", fmt::format("{} parameters cannot be fitted to {} residuals: fewer "
                                                     "parameters or more points",
                                                     p, m));
  // weights: the given noise, else the data's scatter (floored: noise-free synthetic data, 1e-9 of the curve's
  // largest value)
  auto largest = [](const std::vector<double>& y) {
    double s = 0.0;
    for (double x : y) s = std::max(s, std::abs(x));
    return s;
  };
  r.frequency_shift_noise = engine::noise(options.frequency_shift_noise, df, false,
                                          std::max(1e-9 * largest(df), 1e-12), r.noise_estimated_frequency_shift);
  r.dissipation_noise = with_e ? engine::noise(options.dissipation_noise, diss, false,
                                               std::max(1e-9 * largest(diss), 1e-40), r.noise_estimated_dissipation)
                               : nan;
  const double sigma_f = r.frequency_shift_noise, sigma_e = with_e ? r.dissipation_noise : 1.0;
  // residuals (n, 2n with dissipation): (Δf_meas − Δf_model − Δf_off)/σ_Δf and (E_meas − E_model)/σ_E
  auto raw = [&](const FmCurveEvaluation& e, const ModelValues& v) {
    Eigen::VectorXd res(m);
    for (std::size_t i = 0; i < n; ++i) {
      const auto k = static_cast<long>(i);
      res[k] = (df[i] - e.frequency_shift[i] - v.frequency_shift_offset) / sigma_f;
      if (with_e) res[static_cast<long>(n) + k] = (diss[i] - e.dissipation[i]) / sigma_e;
    }
    return res;
  };
  const FmForwardModel model(settings, options, distance);
  engine::Problem<FmForwardModel> problem(model, options, r.parameters, m, raw);
  const auto [e, v] = engine::solve(problem, options, r);

  r.distance = distance;
  r.frequency_shift = df;
  r.dissipation = diss;
  for (std::size_t k = 0; k < n; ++k) r.fitted_frequency_shift.push_back(e.frequency_shift[k] + v.frequency_shift_offset);
  if (with_e) r.fitted_dissipation = e.dissipation;
  r.contact = e.contact;
  r.jumped = e.jumped;
  r.rms_frequency_shift = rms(df, r.fitted_frequency_shift);
  r.rms_dissipation = with_e ? rms(diss, r.fitted_dissipation) : nan;
  r.amplitude_noise = r.phase_noise = r.rms_amplitude = r.rms_phase = nan;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace afmkit::spectroscopy
