// The quasi-static tip engine (quasi_static.hpp).
#include "afmkit/tapping/image/quasi_static.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::tapping::image {

QuasiStaticEngine::QuasiStaticEngine(const OrbitMap& map, const UnitScales& scales, double time_constant,
                                     double lockin_bandwidth)
    : map_(map), scales_(scales), hints_(map.branches().size(), 0) {
  // physical model units: nm, nN, aJ, s (units.hpp)
  metres_ = scales.length * 1e-9;
  newtons_ = scales.force * 1e-9;
  watts_ = scales.energy * 1e-18 / (map.drive_period() * scales.time);
  if (!(time_constant >= 0.0 && std::isfinite(time_constant)))
    throw InvalidParameter("time_constant", fmt::format("the cantilever's time constant {} s must be >= 0",
                                                        time_constant));
  if (!(lockin_bandwidth >= 0.0 && std::isfinite(lockin_bandwidth)))
    throw InvalidParameter("lockin_bandwidth",
                           fmt::format("lockin_bandwidth = {} Hz is out of range: must be >= 0", lockin_bandwidth));
  cantilever_ = PhasorLag(time_constant);
  lockin_ = PhasorLag(lockin_time_constant(lockin_bandwidth));
}

OrbitMap::Engaged engage_on(const OrbitMap& map, double amplitude, double metres) {
  const OrbitMap::Engaged e = map.engage(amplitude / metres);
  if (e.branch < 0)
    throw InvalidParameter(
        "setpoint", fmt::format("the approach from map_separation_max = {:.6g} m down to map_separation_min = {:.6g} m "
                                "never brings the amplitude down to the set-point {:.6g} m: raise the setpoint or "
                                "lower map_separation_min",
                                map.separation_max() * metres, map.separation_min() * metres, amplitude));
  return e;
}

double QuasiStaticEngine::engage(double amplitude) {
  const OrbitMap::Engaged e = engage_on(map_, amplitude, metres_);
  branch_ = e.branch;
  const SteadyState s = map_.at(branch_, e.separation);
  const std::complex<double> settled(s.amplitude * metres_ * s.cos_phase, s.amplitude * metres_ * s.sin_phase);
  cantilever_.reset(settled);
  lockin_.reset(settled);
  return e.separation * metres_;
}

TipReading QuasiStaticEngine::advance(const scan::Surface& surface, double z, double x0, double x1, double y,
                                      double dt) {
  TipReading r;
  const double h = surface(0.5 * (x0 + x1), y);
  r.separation = z - h;
  double l = r.separation / metres_;
  if (!(l >= map_.separation_min() && l <= map_.separation_max())) {  // NaN too
    r.beyond_map = true;
    l = l > map_.separation_max() ? map_.separation_max() : map_.separation_min();
  }
  branch_ = map_.follow(branch_, l);
  const SteadyState s = map_.at(branch_, l, hints_[static_cast<std::size_t>(branch_)]);
  // the lags act on X + iY = B e^{iφ}, the input held over the step (zero-order hold)
  const double a = s.amplitude * metres_;
  const std::complex<double> target(a * s.cos_phase, a * s.sin_phase);
  const std::complex<double> out = lockin_.step(cantilever_.step(target, dt), dt);
  r.amplitude = std::sqrt(out.real() * out.real() + out.imag() * out.imag());
  r.in_phase = out.real();
  r.quadrature = out.imag();
  r.peak_force = s.peak_force * newtons_;
  r.power = s.contact_dissipation * watts_;
  r.regime = static_cast<int>(regime_of(s.in_phase_force, map_.drive_amplitude()));
  r.branch = branch_;
  return r;
}

}  // namespace afmkit::tapping::image
