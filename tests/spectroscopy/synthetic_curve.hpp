#pragma once
// Synthetic raw force curves from a known model, for the preparation tests: the tip at the equilibrium of the
// cantilever (k·d = F(gap)) over a piezo ramp, measured as a photodetector signal with a baseline offset and tilt
// and Gaussian noise of a fixed seed.
#include <cmath>
#include <functional>
#include <random>

#include "afmkit/io/curves/raw_curve.hpp"

namespace afmkit_test {

struct SyntheticModel {
  double k = 0.1;             // N/m
  double invols = 50e-9;      // m/V
  double contact = 2.0e-6;    // x_c: tip position where the contact (Hertz term) starts [m]
  double z_top = 5.0e-6, z_bottom = 1.0e-6;  // piezo ramp [m]
  std::size_t samples = 1500;  // per segment
  double offset = 20e-9;      // baseline deflection offset b0 [m]
  double tilt = 4e-3;         // baseline deflection tilt b1 [m/m]
  double noise_volts = 2e-3;  // σ of the signal [V]
  unsigned seed = 12345;
  // force of the gap s = x − x_c (s < 0: indentation); branch 0 approach, 1 retract
  std::function<double(double s, int branch)> force;
  double window_below = 0, window_above = 0;  // x − z search window for the equilibrium [m] (d range)
  double step = 0;                            // scan step of the window [m]
};

/// The equilibrium tip position x for piezo z: the largest root of k(x − z) − F(x − x_c) (approach: the far branch
/// until it vanishes) or the smallest (retract), by a scan of the window and bisection.
inline double equilibrium(const SyntheticModel& m, double z, int branch) {
  auto g = [&](double x) { return m.k * (x - z) - m.force(x - m.contact, branch); };
  const double lo = z + m.window_below, hi = z + m.window_above;
  const std::size_t n = static_cast<std::size_t>((hi - lo) / m.step) + 1;
  double best = std::nan("");
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const std::size_t j = branch == 0 ? n - 2 - i : i;  // approach: from the top
    double a = lo + static_cast<double>(j) * m.step, b = a + m.step;
    double ga = g(a), gb = g(b);
    if ((ga <= 0) == (gb <= 0)) continue;
    for (int it = 0; it < 80; ++it) {
      const double c = 0.5 * (a + b), gc = g(c);
      if ((gc <= 0) == (ga <= 0)) { a = c; ga = gc; } else { b = c; }
    }
    best = 0.5 * (a + b);
    break;
  }
  return best;
}

/// The raw curve: approach (z decreasing) and retract (z increasing), deflection_volts only.
inline afmkit::io::curves::RawCurve synthetic_curve(const SyntheticModel& m) {
  using afmkit::io::curves::SegmentKind;
  afmkit::io::curves::RawCurve raw;
  raw.origin = "synthetic";
  raw.metadata.spring_constant = m.k;
  raw.metadata.invols = m.invols;
  std::mt19937_64 rng(m.seed);
  std::normal_distribution<double> noise(0.0, m.noise_volts);
  for (int branch = 0; branch < 2; ++branch) {
    afmkit::io::curves::Segment s;
    s.kind = branch == 0 ? SegmentKind::approach : SegmentKind::retract;
    for (std::size_t i = 0; i < m.samples; ++i) {
      const double t = static_cast<double>(i) / static_cast<double>(m.samples - 1);
      const double z = branch == 0 ? m.z_top + t * (m.z_bottom - m.z_top) : m.z_bottom + t * (m.z_top - m.z_bottom);
      const double d = equilibrium(m, z, branch) - z;
      s.height.push_back(z);
      s.deflection_volts.push_back((d + m.offset + m.tilt * z) / m.invols + noise(rng));
    }
    raw.segments.push_back(std::move(s));
  }
  return raw;
}

}  // namespace afmkit_test
