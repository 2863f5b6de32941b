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
  time_constant_ = time_constant;
  lockin_time_constant_ = lockin_bandwidth > 0.0 ? 1.0 / (2.0 * std::numbers::pi * lockin_bandwidth) : 0.0;
}

double QuasiStaticEngine::engage(double amplitude) {
  const OrbitMap::Engaged e = map_.engage(amplitude / metres_);
  if (e.branch < 0)
    throw InvalidParameter(
        "setpoint", fmt::format("the approach from map_separation_max = {:.6g} m down to map_separation_min = {:.6g} m "
                                "never brings the amplitude down to the set-point {:.6g} m: raise the setpoint or "
                                "lower map_separation_min",
                                map_.separation_max() * metres_, map_.separation_min() * metres_, amplitude));
  branch_ = e.branch;
  const SteadyState s = map_.at(branch_, e.separation);
  cantilever_re_ = lockin_re_ = s.amplitude * metres_ * s.cos_phase;
  cantilever_im_ = lockin_im_ = s.amplitude * metres_ * s.sin_phase;
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
  if (dt != last_dt_) {  // exact first-order lags over a step with the input held (zero-order hold)
    last_dt_ = dt;
    decay_c_ = time_constant_ > 0.0 ? std::exp(-dt / time_constant_) : 0.0;
    decay_li_ = lockin_time_constant_ > 0.0 ? std::exp(-dt / lockin_time_constant_) : 0.0;
  }
  const double a = s.amplitude * metres_;
  const double target_re = a * s.cos_phase, target_im = a * s.sin_phase;  // X + iY = B e^{iφ}
  cantilever_re_ = target_re + decay_c_ * (cantilever_re_ - target_re);
  cantilever_im_ = target_im + decay_c_ * (cantilever_im_ - target_im);
  lockin_re_ = cantilever_re_ + decay_li_ * (lockin_re_ - cantilever_re_);
  lockin_im_ = cantilever_im_ + decay_li_ * (lockin_im_ - cantilever_im_);
  r.amplitude = std::sqrt(lockin_re_ * lockin_re_ + lockin_im_ * lockin_im_);
  r.in_phase = lockin_re_;
  r.quadrature = lockin_im_;
  r.peak_force = s.peak_force * newtons_;
  r.power = s.contact_dissipation * watts_;
  r.regime = static_cast<int>(regime_of(s.in_phase_force, map_.drive_amplitude()));
  r.branch = branch_;
  return r;
}

}  // namespace afmkit::tapping::image
