#include "afmkit/control/harmonic_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::control {

std::vector<std::complex<double>> fourier_coefficients(std::span<const double> x, int max_order) {
  const auto m = static_cast<long>(x.size());
  if (m == 0) throw InvalidParameter("one_period", "fourier_coefficients: the period has no samples");
  if (max_order < 0 || 2L * max_order >= m)
    throw InvalidParameter("max_order", fmt::format("max_order = {} is out of range: must be in [0, {}) for {} "
                                                    "samples per period (below Nyquist)",
                                                    max_order, (m + 1) / 2, m));
  std::vector<std::complex<double>> c(max_order + 1);
  double mean = 0.0;
  for (double v : x) mean += v;
  c[0] = mean / static_cast<double>(m);
  std::vector<std::complex<double>> unit(static_cast<std::size_t>(m));  // e^{−2πij/m}
  for (long j = 0; j < m; ++j) unit[j] = std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(j) / m);
  for (int k = 1; k <= max_order; ++k) {
    std::complex<double> acc = 0.0;
    long idx = 0;  // k·n mod m (exact argument reduction)
    for (long n = 0; n < m; ++n) {
      acc += x[n] * unit[idx];
      idx += k;
      if (idx >= m) idx -= m;
    }
    c[k] = 2.0 * acc / static_cast<double>(m);
  }
  return c;
}

std::complex<double> disturbance_harmonic(const Disturbance::Harmonic& h) {
  return std::complex<double>(0.0, -1.0) * std::polar(h.amplitude, h.phase);
}

std::complex<double> disturbance_harmonic(const Disturbance& f, int k) {
  if (k == 0) return f.offset;
  for (const auto& h : f.harmonics)
    if (h.order == k) return disturbance_harmonic(h);
  return 0.0;
}

namespace {
std::complex<double> uncontrolled_of(const Plant& plant, std::complex<double> fk, int k) {
  if (plant.kind == PlantKind::Static) return fk;
  const double g = plant.rate;
  return g * fk / std::complex<double>(g, k * plant.rotation_frequency);
}
}  // namespace

std::complex<double> uncontrolled_harmonic(const Plant& plant, int k) {
  return uncontrolled_of(plant, disturbance_harmonic(plant.disturbance, k), k);
}

std::complex<double> uncontrolled_harmonic(const Plant& plant, const Disturbance::Harmonic& h) {
  return uncontrolled_of(plant, disturbance_harmonic(h), h.order);
}

namespace {
double output_without(const Plant& plant, double t, std::span<const int> rejected) {
  double y = plant.disturbance.offset;
  const double theta = plant.rotation_frequency * t;
  for (const auto& h : plant.disturbance.harmonics) {
    if (std::find(rejected.begin(), rejected.end(), h.order) != rejected.end()) continue;
    const std::complex<double> ck = uncontrolled_harmonic(plant, h);  // O(1): the whole sum is O(K)
    y += (ck * std::polar(1.0, h.order * theta)).real();
  }
  return y;
}
}  // namespace

double uncontrolled_output(const Plant& plant, double t) { return output_without(plant, t, {}); }

double target_output(const Plant& plant, double t, std::span<const int> rejected) {
  return output_without(plant, t, rejected);
}

EnvelopeFit fit_log_envelope(std::span<const double> env, double period) {
  const int n = static_cast<int>(env.size());
  EnvelopeFit fit{std::numeric_limits<double>::quiet_NaN(), 0, -1};
  if (n < 2) return fit;
  int first = 1, last = n - 1;
  if (n >= 4 && env[n - 1] > 2.0 * env[n / 2]) {
    first = n / 2;  // growing: the dominant (rightmost) mode has taken over in the second half
  } else {
    // decaying: stop before the floor (integrator/rounding level) is reached; if the envelope never comes
    // within 100× of its minimum after period 1 (no floor reached), the whole run is used
    const double floor = *std::min_element(env.begin(), env.end());
    int end = n - 1;
    while (end > 0 && env[end] <= 100.0 * floor) --end;
    if (end >= first + 2) last = end;
    if (n == 2) first = 0;
  }
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int cnt = 0;
  for (int p = first; p <= last; ++p) {
    if (!(env[p] > 0.0) || !std::isfinite(env[p])) continue;
    const double t = (p + 0.5) * period, y = std::log(env[p]);
    sx += t;
    sy += y;
    sxx += t * t;
    sxy += t * y;
    ++cnt;
  }
  fit.first_period = first;
  fit.last_period = last;
  if (cnt < 2) return fit;
  const double den = cnt * sxx - sx * sx;
  if (den > 0.0) fit.growth_rate = (cnt * sxy - sx * sy) / den;
  return fit;
}

}  // namespace afmkit::control
