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
  for (int i = 0; i < points; ++i) {
    const double t = static_cast<double>(i) / (points - 1);
    w[i] = log_spacing ? lo * std::pow(hi / lo, t) : lo + (hi - lo) * t;
  }
  w.front() = lo;
  w.back() = hi;
  return w;
}

std::vector<double> unwrap_phase(std::vector<double> p) {
  const double two_pi = 2.0 * std::numbers::pi;
  double offset = 0.0, last = std::nan("");
  for (double& x : p) {
    if (!std::isfinite(x)) continue;
    if (std::isfinite(last)) {
      const double raw = x + offset;
      const double jump = raw - last;
      if (std::abs(jump) > std::numbers::pi) offset -= two_pi * std::round(jump / two_pi);
    }
    x += offset;
    last = x;
  }
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
    const bool infinite = std::isinf(v.real()) || std::isinf(v.imag());
    r.magnitude[i] = infinite ? INFINITY : std::abs(v);
    r.phase[i] = infinite || std::isnan(v.real()) || std::isnan(v.imag()) ? std::nan("") : std::arg(v);
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
