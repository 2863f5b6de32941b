#include "afmkit/control/frequency_response.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

std::vector<double> frequency_grid(double lo, double hi, int points, bool log_spacing) {
  validate::non_negative("omega_min", lo);
  validate::positive("omega_max", hi);
  validate::require(hi > lo, "omega_max", hi, fmt::format("> omega_min = {}", lo));
  validate::in_range("points", static_cast<long>(points), 2L, 100000000L);
  if (log_spacing) validate::positive("omega_min", lo);
  std::vector<double> w(points);
  for (int i = 0; i < points; ++i) w[i] = frequency_grid_point(lo, hi, points, log_spacing, i);
  return w;
}

double frequency_grid_point(double lo, double hi, long points, bool log_spacing, long i) {
  if (i <= 0) return lo;
  if (i >= points - 1) return hi;
  const double t = static_cast<double>(i) / static_cast<double>(points - 1);
  // log grid as exp of a linear one: hi/lo may overflow (e.g. 10/1e-308) where log(lo), log(hi) do not
  return log_spacing ? std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * t) : lo + (hi - lo) * t;
}

double PhaseUnwrapper::operator()(double x) {
  if (!std::isfinite(x)) return x;
  if (std::isfinite(last_)) {
    const double two_pi = 2.0 * std::numbers::pi;
    const double jump = x + offset_ - last_;
    if (std::abs(jump) > std::numbers::pi) offset_ -= two_pi * std::round(jump / two_pi);
  }
  last_ = x + offset_;
  return last_;
}

void magnitude_phase(std::complex<double> v, double& magnitude, double& raw_phase) {
  const bool infinite = std::isinf(v.real()) || std::isinf(v.imag());
  magnitude = infinite ? INFINITY : std::abs(v);
  raw_phase = infinite || std::isnan(v.real()) || std::isnan(v.imag()) ? std::nan("") : std::arg(v);
}

std::vector<double> unwrap_phase(std::vector<double> p) {
  PhaseUnwrapper unwrap;
  for (double& x : p) x = unwrap(x);
  return p;
}

FrequencyResponse frequency_response(const FrequencyFunction& g, std::span<const double> omegas) {
  FrequencyResponse r;
  r.omega.assign(omegas.begin(), omegas.end());
  r.response.resize(omegas.size());
  r.magnitude.resize(omegas.size());
  r.phase.resize(omegas.size());
  for (std::size_t i = 0; i < omegas.size(); ++i) {
    validate::finite("omega", omegas[i]);
    const std::complex<double> v = g({0.0, omegas[i]});
    r.response[i] = v;
    magnitude_phase(v, r.magnitude[i], r.phase[i]);
  }
  r.phase = unwrap_phase(std::move(r.phase));
  return r;
}

FrequencyResponse frequency_response(const StateSpace& sys, std::span<const double> omegas) {
  if (!sys.is_siso()) throw InvalidParameter("system", "system: frequency_response needs a SISO system");
  return frequency_response([&](std::complex<double> s) { return sys(s); }, omegas);
}

FrequencyResponse frequency_response(const TransferFunction& sys, std::span<const double> omegas) {
  return frequency_response([&](std::complex<double> s) { return sys(s); }, omegas);
}

FrequencyResponse frequency_response(const Controller& c, std::span<const double> omegas) {
  return frequency_response([&](std::complex<double> s) { return controller_response(c, s); }, omegas);
}

std::complex<double> evaluate(const LoopSpec& loop, LoopSystem which, std::complex<double> s) {
  switch (which) {
    case LoopSystem::Controller: return controller_response(loop.controller, s);
    case LoopSystem::Plant: return plant_response(loop, s);
    case LoopSystem::Loop: return loop_response(loop, s);
    case LoopSystem::Sensitivity: return sensitivity(loop, s);
    case LoopSystem::ClosedLoop: return disturbance_response(loop, s);
  }
  return {};
}

FrequencyResponse frequency_response(const LoopSpec& loop, LoopSystem which, std::span<const double> omegas) {
  return frequency_response([&](std::complex<double> s) { return evaluate(loop, which, s); }, omegas);
}

}  // namespace afmkit::control
