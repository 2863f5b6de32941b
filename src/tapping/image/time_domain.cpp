// The exact time-domain tip engine (time_domain.hpp).
#include "afmkit/tapping/image/time_domain.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <optional>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/image/quasi_static.hpp"
#include "afmkit/tapping/image/cycle_integrals.hpp"
#include "afmkit/tapping/simulation.hpp"

namespace afmkit::tapping::image {

void TimeDomainOptions::validate() const {
  if (!(lockin_cycles >= 1 && lockin_cycles <= 1000000))
    throw InvalidParameter("lockin_cycles", fmt::format("lockin_cycles = {} is out of range: the lock-in averages a "
                                                        "whole number of drive cycles in [1, 1000000]",
                                                        lockin_cycles));
  if (!(lockin_bandwidth >= 0.0 && std::isfinite(lockin_bandwidth)))
    throw InvalidParameter("lockin_bandwidth",
                           fmt::format("lockin_bandwidth = {} Hz is out of range: must be >= 0", lockin_bandwidth));
  if (!(cycle_tolerance > 0.0 && cycle_tolerance < 1.0))
    throw InvalidParameter("cycle_tolerance", fmt::format("cycle_tolerance = {} is out of range: the cycles' relative "
                                                          "tolerance must be in (0, 1)",
                                                          cycle_tolerance));
  shooting.validate();
}

namespace {
TimeDomainOptions validated(const TimeDomainOptions& o) {
  o.validate();
  return o;
}
}  // namespace

/// One drive cycle: the lock-in's X + iY of it [model length], the first harmonic of the tip–sample force
/// ∫ H e^{−iωt} dt, the largest force and the energy the sample took.
struct TimeDomainEngine::Cycle {
  std::complex<double> first_harmonic;  // ∫ x e^{−iωt} dt over the cycle
  std::complex<double> force_harmonic;  // ∫ H e^{−iωt} dt over the cycle
  double peak_force = 0.0, dissipation = 0.0;
};

TimeDomainEngine::TimeDomainEngine(const TappingModel& model, const OrbitMap& map, const UnitScales& scales,
                                   const TimeDomainOptions& options)
    : map_(map),
      system_(model),
      simulation_(validated(options).shooting.simulation),
      shooting_(options.shooting),
      omega_(model.drive.frequency),
      model_period_(model.period()),
      period_(model.period() * scales.time),
      lockin_(options.lockin_cycles, model.period() * scales.time, options.lockin_bandwidth) {
  simulation_.sensitivity = false;
  simulation_.relative_tolerance = options.cycle_tolerance;
  simulation_.absolute_tolerance = 1e-2 * options.cycle_tolerance;
  // the adaptive integrator's largest step: a twelfth of the shortest period instead of a 24th (its guards still see
  // every crossing: the gap's rate ẋ changes sign at most once in a twelfth of a period); the error control sets the
  // steps below it (docs/theory-tapping.md#time-domain-imaging: steps per cycle against the tolerance)
  if (resolve_integrator(model, simulation_.integrator) == Integrator::adaptive) {
    simulation_.max_step_fraction = kCycleMaxStepFraction;
    // H_c by parts (advance) is exact for the integrated motion only to the integrator's error: at resonance its
    // (ω_n² − ω² + icω) ∫x e^{−iωt} term cancels ΓT/2, so a relative error ε of the cycle's ∫x e^{−iωt} leaves
    // ~ε Γ (measured: 0.6 rtol Γ on free cycles); below 10 rtol Γ a cycle is not told from free
    free_fraction_ = std::max(free_fraction_, 10.0 * simulation_.relative_tolerance);
  }
  metres_ = scales.length * 1e-9;  // physical model units: nm, nN, aJ, s (units.hpp)
  newtons_ = scales.force * 1e-9;
  watts_ = scales.energy * 1e-18 / period_;
}

TimeDomainEngine::Cycle TimeDomainEngine::run_cycle(double separation) {
  system_.set_separation(separation);
  CycleIntegrals integrals(model_period_);
  const TipState a = state_;
  const double t0 = start_, t1 = start_ + model_period_;
  simulation_.initial_step = next_step_;  // the step the last cycle ended with, not 1e-3 of a period again
  const SimulationResult r = simulate(system_, t0, a, t1, simulation_, &integrals);
  next_step_ = r.stats.next_step;
  state_ = r.state;
  events_ += r.stats.events;
  steps_ += r.stats.steps;
  ++cycles_;
  // ∫ H e^{−iωt} dt from eq. 8 (H = ẍ + cẋ + ω_n² x − Γ cos ωt) integrated by parts over the cycle: exact for any
  // motion, periodic or not (E = e^{−iωt}): [ẋE] + (iω + c)[xE] + (ω_n² − ω² + icω) ∫xE − ΓT/2
  const std::complex<double> i(0.0, 1.0);
  const std::complex<double> e0 = std::polar(1.0, -omega_ * t0), e1 = std::polar(1.0, -omega_ * t1);
  const double c = system_.damping(), k = system_.stiffness(), w = omega_, gamma = system_.model().drive.amplitude;
  const std::complex<double> f1 = integrals.first_harmonic;
  const std::complex<double> dx = state_.position * e1 - a.position * e0;  // [xE]
  Cycle out;
  out.first_harmonic = f1;
  out.force_harmonic =
      (state_.velocity * e1 - a.velocity * e0) + (i * w + c) * dx + (k - w * w + i * c * w) * f1 - 0.5 * gamma * model_period_;
  out.peak_force = integrals.peak_force;
  // the energy the sample takes, ∫ h ẋ dt, by the energy balance (cycle_integrals.hpp)
  const double energy0 = 0.5 * (a.velocity * a.velocity + k * a.position * a.position);
  const double energy1 = 0.5 * (state_.velocity * state_.velocity + k * state_.position * state_.position);
  out.dissipation = gamma * (dx.real() - w * f1.imag()) - c * integrals.velocity_square - (energy1 - energy0);
  return out;
}

double TimeDomainEngine::engage(double amplitude) {
  simulation_.initial_step = 0.0;  // the engagement's runs start afresh (an engine may engage again)
  const OrbitMap::Engaged e = engage_on(map_, amplitude, metres_);
  const SteadyState s = map_.at(e.branch, e.separation);
  // the periodic orbit there: shooting from the map's first harmonic x ≈ B cos(ωt − φ) at t = 0; then the separation
  // where the orbit's own amplitude is the set-point (secant, from the map's interpolated one)
  const TipState guess{s.amplitude * s.cos_phase, omega_ * s.amplitude * s.sin_phase};
  const double target = amplitude / metres_;
  const auto amplitude_at = [&](double l, TipState& y) -> double {  // NaN: no stable orbit of the map's amplitude
    system_.set_separation(l);
    const std::optional<PeriodicOrbit> orbit = try_shoot(system_.model(), y, 1, shooting_);
    if (!orbit || !orbit->stable) return std::numeric_limits<double>::quiet_NaN();
    CycleIntegrals cycle(model_period_);
    simulate(system_, 0.0, orbit->initial, model_period_, simulation_, &cycle);
    const double b = 2.0 * std::abs(cycle.first_harmonic) / model_period_;
    if (!(std::abs(b - s.amplitude) <= 0.02 * s.amplitude)) return std::numeric_limits<double>::quiet_NaN();
    y = orbit->initial;
    return b;
  };
  double l = e.separation;
  TipState y = guess;
  double b = amplitude_at(l, y);
  shot_ = std::isfinite(b);
  if (shot_) {
    const double h = 1e-3 * (map_.separation_max() - map_.separation_min());
    double l_prev = l + h, b_prev = map_.at(e.branch, l + h).amplitude - s.amplitude + b;  // the map's slope
    for (int it = 0; it < 8 && std::abs(b - target) > 1e-9 * target && b != b_prev; ++it) {
      const double next = l - (b - target) * (l - l_prev) / (b - b_prev);
      if (!(std::abs(next - l) <= 10.0 * h)) break;  // not near the engaged orbit: keep the last one
      TipState y_next = y;
      const double b_next = amplitude_at(next, y_next);
      if (!std::isfinite(b_next)) break;
      l_prev = l;
      b_prev = b;
      l = next;
      b = b_next;
      y = y_next;
    }
    if (!(std::abs(b - target) <= 1e-6 * target)) {  // the secant did not settle: the map's separation
      l = e.separation;
      y = guess;
      b = amplitude_at(l, y);
      shot_ = std::isfinite(b);
    }
  }
  system_.set_separation(l);
  state_ = shot_ ? y : guess;
  start_ = 0.0;
  next_step_ = 0.0;
  if (!shot_) {  // ten cantilever time constants 2Q/ω_n
    const double settle = 20.0 * system_.model().cantilever.quality_factor / system_.model().cantilever.natural_frequency;
    const long n = static_cast<long>(std::ceil(settle / model_period_));
    state_ = simulate(system_, 0.0, state_, static_cast<double>(n) * model_period_, simulation_).state;
  }
  // cycles from the top of the orbit: ωt − φ = 0 (mod 2π)
  double phase = s.phase();
  if (phase < 0.0) phase += 2.0 * std::numbers::pi;
  start_ = phase / omega_;
  if (start_ > 0.0) state_ = simulate(system_, 0.0, state_, start_, simulation_).state;
  // the lock-in settled on a cycle of the engaged orbit
  const Cycle c = run_cycle(l);
  const std::complex<double> xy = std::conj(2.0 * c.first_harmonic / model_period_) * metres_;  // B e^{iφ} [m]
  lockin_.reset(xy);
  cycles_ = events_ = steps_ = 0;
  clock_ = target_ = 0.0;
  last_ = {};
  last_.amplitude = std::abs(xy);
  last_.in_phase = xy.real();
  last_.quadrature = xy.imag();
  last_.separation = l * metres_;
  return l * metres_;
}

TipReading TimeDomainEngine::advance(const scan::Surface& surface, double z, double x0, double x1, double y,
                                     double dt) {
  const double begin = target_;
  target_ += dt;
  // whole cycles that end by the target (a relative slack of 1e-9 of a cycle against the rounding of the clock)
  const long n = static_cast<long>(std::floor((target_ - clock_) / period_ + 1e-9));
  if (n < 1) return last_;  // the controller period ends inside this cycle: the lock-in still shows the last one
  std::complex<double> harmonic = 0.0, force = 0.0;
  double peak = -std::numeric_limits<double>::infinity(), dissipation = 0.0, separation = 0.0;
  std::complex<double> out;
  for (long k = 0; k < n; ++k) {
    // the tip's lateral position at the middle of the cycle (on [x0, x1]: the scan moves linearly over dt)
    const double mid = clock_ + (static_cast<double>(k) + 0.5) * period_;
    const double f = std::clamp((mid - begin) / dt, 0.0, 1.0);
    separation = z - surface(x0 + f * (x1 - x0), y);
    const Cycle c = run_cycle(separation / metres_);
    out = lockin_.step(std::conj(2.0 * c.first_harmonic / model_period_) * metres_);
    harmonic += c.first_harmonic;
    force += c.force_harmonic;
    peak = std::max(peak, c.peak_force);
    dissipation += c.dissipation;
  }
  clock_ += static_cast<double>(n) * period_;
  TipReading r;
  r.amplitude = std::abs(out);
  r.in_phase = out.real();
  r.quadrature = out.imag();
  r.separation = separation;
  r.peak_force = peak * newtons_;
  r.power = dissipation / static_cast<double>(n) * watts_;
  // H_c = (2/nT) Re(e^{iφ} ∫ H e^{−iωt} dt) over the cycles, φ their lag (orbit_map.hpp: its sign is the regime)
  const double norm = std::abs(harmonic);
  const std::complex<double> lag = norm > 0.0 ? std::conj(harmonic) / norm : std::complex<double>(1.0, 0.0);
  const double in_phase_force = 2.0 / (static_cast<double>(n) * model_period_) * (lag * force).real();
  r.regime = static_cast<int>(regime_of(in_phase_force, system_.model().drive.amplitude, free_fraction_));
  r.branch = r.regime;  // a change of regime is the time-domain engine's jump
  last_ = r;
  return r;
}

}  // namespace afmkit::tapping::image
