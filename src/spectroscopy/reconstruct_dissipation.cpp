// Dissipated energy per cycle and the branch difference it implies (reconstruct_am.hpp,
// docs/reconstruction.md#dissipation).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "afmkit/spectroscopy/reconstruct_am.hpp"

namespace afmkit::spectroscopy {

namespace {
/// |1 − r² + i r/Q|: the free response's inverse transfer function at the drive (drive force = k A0 · this).
double free_modulus(const AmSettings& s) {
  const double r = s.frequency_ratio();
  return std::hypot(1.0 - r * r, r / s.quality_factor);
}
}  // namespace

double dissipated_energy(double a, double phase, const AmSettings& s) {
  // first-harmonic energy balance: drive work π F_d A sin φ = viscous loss π k A² r/Q + E_dis
  const double r = s.frequency_ratio();
  return std::numbers::pi * s.spring_constant * a *
         (s.free_amplitude * free_modulus(s) * std::sin(phase) - a * r / s.quality_factor);
}

double equivalent_frequency_shift(double a, double phase, const AmSettings& s) {
  // in-phase balance: (1/π)∮ F cos θ dθ = k A (1 − r²) − F_d cos φ, and Ω = −(1/(2kA)) (1/π)∮ F cos θ dθ
  const double r = s.frequency_ratio();
  return -0.5 * (1.0 - r * r) + s.free_amplitude * free_modulus(s) * std::cos(phase) / (2.0 * a);
}

std::vector<double> branch_difference(const std::vector<double>& gap, const std::vector<double>& dissipation,
                                      double threshold, double& contact_gap) {
  const std::size_t n = gap.size();
  std::vector<double> e(n);
  for (std::size_t i = 0; i < n; ++i) e[i] = std::max(0.0, dissipation[i]);
  e = isotonic_nonincreasing(e);
  std::size_t last = n;  // the last point above the threshold
  for (std::size_t i = 0; i < n; ++i)
    if (e[i] > threshold) last = i;
  std::vector<double> out(n, 0.0);
  contact_gap = std::numeric_limits<double>::quiet_NaN();
  if (last == n) return out;
  for (std::size_t i = last + 1; i < n; ++i) e[i] = 0.0;
  std::vector<double> seg(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) seg[i] = (e[i] - e[i + 1]) / (gap[i + 1] - gap[i]);
  for (std::size_t i = 0; i < n; ++i) {
    if (i == 0) out[i] = seg[0];
    else if (i + 1 == n) out[i] = seg[n - 2];
    else out[i] = 0.5 * (seg[i - 1] + seg[i]);
  }
  contact_gap = gap[std::min(last + 1, n - 1)];
  return out;
}

}  // namespace afmkit::spectroscopy
