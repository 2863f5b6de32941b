#pragma once
// Test-only reference for the tapping model with any force law: classical RK4 with step-doubling error control
// (adaptive), and every event — the gap crossing a switching gap, ẋ changing sign where the branches differ —
// located by bisection on the length of the last step. Within a mode the force is the mode's branch at the gap
// clamped into the mode's region. Independent of the library's integrators, guards and Boost.Odeint.
// A contact-aware law (docs/force-laws.md#hysteresis) adds the memory of contact to the mode: set when the gap
// falls below the contact gap, cleared when it rises above the release gap; free, the force is H_a.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "afmkit/tapping/model.hpp"

namespace afmkit_test {

struct HybridState {
  double x, v;
};

class ReferenceHybrid {
 public:
  explicit ReferenceHybrid(const afmkit::tapping::TappingModel& m) : m_(m), gaps_(m.law.switching_gaps()) {}

  /// State at t_end from (t0, s), relative local tolerance `tol`.
  HybridState run(double t0, HybridState s, double t_end, double tol) const {
    double t = t0, h = 1e-3;
    Mode mode = mode_of(t, s);
    long guard = 0;
    while (t < t_end) {
      if (++guard > 50'000'000) throw std::runtime_error("reference: too many steps");
      h = std::min(h, t_end - t);
      // step doubling
      const HybridState full = rk4(mode, t, s, h);
      const HybridState half = rk4(mode, t + 0.5 * h, rk4(mode, t, s, 0.5 * h), 0.5 * h);
      const double err = std::max(std::abs(full.x - half.x), std::abs(full.v - half.v)) / 15.0;
      const double scale = tol * std::max(1.0, std::max(std::abs(s.x), std::abs(s.v)));
      if (err > scale) {
        h *= std::max(0.2, 0.9 * std::pow(scale / err, 0.2));
        continue;
      }
      HybridState next{half.x + (half.x - full.x) / 15.0, half.v + (half.v - full.v) / 15.0};
      if (fired(mode, next)) {
        // bisection on the step length: largest k with no event
        double lo = 0.0, hi = h;
        for (int i = 0; i < 200 && hi - lo > 1e-15 * std::max(1.0, t); ++i) {
          const double mid = 0.5 * (lo + hi);
          (fired(mode, advance(mode, t, s, mid)) ? hi : lo) = mid;
        }
        s = advance(mode, t, s, hi);
        t += hi;
        mode = after_event(mode, t, s);
        h = std::max(h * 0.5, 1e-6);
        continue;
      }
      s = next;
      t += h;
      if (err < 0.1 * scale) h *= std::min(2.0, 0.9 * std::pow(scale / std::max(err, 1e-300), 0.2));
    }
    return s;
  }

 private:
  struct Mode {
    int region;
    bool departure;
    bool contact = false;
  };
  bool aware() const { return m_.law.contact_aware(); }
  bool memory_after(bool before, double d) const {
    if (!aware()) return false;
    if (d < m_.law.contact_gap()) return true;
    if (d >= m_.law.release_gap()) return false;
    return before;
  }
  const afmkit::tapping::TappingModel& m_;
  std::vector<double> gaps_;

  double lo(int r) const { return r == 0 ? -INFINITY : gaps_[r - 1]; }
  double hi(int r) const { return r == static_cast<int>(gaps_.size()) ? INFINITY : gaps_[r]; }
  int region(double d) const { return static_cast<int>(std::upper_bound(gaps_.begin(), gaps_.end(), d) - gaps_.begin()); }
  // whether the branches differ somewhere in region r (sampled; an unbounded side is sampled over 50 nm)
  bool differs(int r) const {
    const double a = std::isfinite(lo(r)) ? lo(r) : hi(r) - 50.0, b = std::isfinite(hi(r)) ? hi(r) : lo(r) + 50.0;
    for (int i = 1; i < 2000; ++i) {
      const double d = a + (b - a) * i / 2000.0;
      if (m_.law.approach(d) != m_.law.departure(d)) return true;
    }
    return false;
  }

  double accel(const Mode& mode, double t, double x, double v) const {
    const double wn = m_.cantilever.natural_frequency;
    double d = x + m_.separation;
    d = std::min(std::max(d, lo(mode.region)), std::nextafter(hi(mode.region), -INFINITY));
    double force = mode.departure && (!aware() || mode.contact) ? m_.law.departure(d) : m_.law.approach(d);
    force -= m_.law.damping(d) * v;
    return m_.drive.amplitude * std::cos(m_.drive.frequency * t) - 2 * m_.cantilever.damping_ratio() * wn * v -
           wn * wn * x + force;
  }
  HybridState rk4(const Mode& mode, double t, HybridState s, double k) const {
    const double k1x = s.v, k1v = accel(mode, t, s.x, s.v);
    const double k2x = s.v + 0.5 * k * k1v, k2v = accel(mode, t + 0.5 * k, s.x + 0.5 * k * k1x, s.v + 0.5 * k * k1v);
    const double k3x = s.v + 0.5 * k * k2v, k3v = accel(mode, t + 0.5 * k, s.x + 0.5 * k * k2x, s.v + 0.5 * k * k2v);
    const double k4x = s.v + k * k3v, k4v = accel(mode, t + k, s.x + k * k3x, s.v + k * k3v);
    return {s.x + k / 6 * (k1x + 2 * k2x + 2 * k3x + k4x), s.v + k / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)};
  }
  // a sub-step of length k split into 8 RK4 steps (accurate where the bisection lands)
  HybridState advance(const Mode& mode, double t, HybridState s, double k) const {
    for (int i = 0; i < 8; ++i) s = rk4(mode, t + i * k / 8, s, k / 8);
    return s;
  }
  bool fired(const Mode& mode, const HybridState& z) const {
    const double d = z.x + m_.separation;
    if (d < lo(mode.region) || d >= hi(mode.region)) return true;
    if (differs(mode.region) && (!aware() || mode.contact)) return mode.departure ? z.v < 0 : z.v > 0;
    return false;
  }
  Mode mode_of(double t, const HybridState& s) const {
    Mode m{region(s.x + m_.separation), s.v > 0, memory_after(false, s.x + m_.separation)};
    if (s.v == 0) m.departure = accel({m.region, true, m.contact}, t, s.x, 0.0) > 0;
    return m;
  }
  Mode after_event(const Mode& mode, double t, const HybridState& s) const {
    const double d = s.x + m_.separation;
    if (d < lo(mode.region) || d >= hi(mode.region)) return {region(d), s.v > 0, memory_after(mode.contact, d)};
    // velocity sign change: the branch that moves away from ẋ = 0
    const bool dep = !mode.departure;
    const double a = accel({mode.region, dep, mode.contact}, t, s.x, 0.0);
    if (dep ? a < 0 : a > 0) throw std::runtime_error("reference: sticking is not modelled");
    return {mode.region, dep, mode.contact};
  }
};

}  // namespace afmkit_test
