// The noise-aware plant inverse: the Wiener low-pass after the exact inverse (wiener_inverse.hpp).
#include "afmkit/scan/wiener_inverse.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "afmkit/core/validate.hpp"

namespace afmkit::scan {

namespace {

constexpr int kGrid = 8192;  // midpoints on (0, π): |H|² peaks near π with width ≈ 1 − |p| (≈ 0.007 rad at 300 kHz)

// |H(ω)|² of the exact inverse H = (1 − a e^{−iω}) / (b1 + b0 e^{−iω}).
double inverse_power(const PlantInverse& inv, double omega) {
  const double c = std::cos(omega), a = inv.decay(), b0 = inv.b0(), b1 = inv.b1();
  return (1.0 - 2.0 * a * c + a * a) / (b1 * b1 + 2.0 * b0 * b1 * c + b0 * b0);
}

}  // namespace

WienerLowPass::WienerLowPass(const PlantInverse& inverse, double noise, double prior_increment) {
  validate::positive("detector_noise", noise);
  validate::positive("prior_increment", prior_increment);
  prior_ = prior_increment;
  const double ratio = (noise / prior_increment) * (noise / prior_increment);  // σ²/A
  std::vector<double> omega(kGrid), power(kGrid), weight(kGrid), difference(kGrid);
  for (int i = 0; i < kGrid; ++i) {
    omega[i] = std::numbers::pi * (i + 0.5) / kGrid;
    power[i] = inverse_power(inverse, omega[i]);
    difference[i] = 2.0 * (1.0 - std::cos(omega[i]));                  // |D|²
    weight[i] = 1.0 / (1.0 + ratio * power[i] * difference[i]);         // W(ω)
  }
  // W within 1e−6 of 1 everywhere (σ²/A → 0): the exact inverse, as it is
  if (*std::min_element(weight.begin(), weight.end()) > 1.0 - 1e-6) {
    taps_ = {1.0};
    noise_gain_ = inverse.noise_gain();
    correlation_ = inverse.noise_correlation();
    cutoff_ = std::numbers::pi;
    return;
  }
  // taps g_k = (1/π)∫₀^π W cos kω dω by the midpoint rule, until they stay below 1e−7 g_0 for 8 in a row
  std::vector<double> g;
  int below = 0;
  for (int k = 0; k <= kMaxHalfWidth; ++k) {
    double sum = 0.0;
    for (int i = 0; i < kGrid; ++i) sum += weight[i] * std::cos(k * omega[i]);
    g.push_back(sum / kGrid);
    below = std::abs(g.back()) < 1e-7 * std::abs(g.front()) ? below + 1 : 0;
    if (below == 8) break;
  }
  if (below == 8) {
    g.resize(g.size() - 8);
  } else {  // cut at kMaxHalfWidth: taper (Hann) so the cut rings less
    const double k_max = static_cast<double>(g.size());
    for (std::size_t k = 0; k < g.size(); ++k)
      g[k] *= 0.5 * (1.0 + std::cos(std::numbers::pi * static_cast<double>(k) / k_max));
  }
  double total = g[0];
  for (std::size_t k = 1; k < g.size(); ++k) total += 2.0 * g[k];
  for (double& v : g) v /= total;
  taps_ = std::move(g);

  // the budget of the taps as applied (wiener_inverse.hpp)
  double noise2 = 0.0, lag1 = 0.0, bias2 = 0.0;
  cutoff_ = std::numbers::pi;
  for (int i = 0; i < kGrid; ++i) {
    double response = taps_[0];
    for (std::size_t k = 1; k < taps_.size(); ++k) response += 2.0 * taps_[k] * std::cos(k * omega[i]);
    noise2 += power[i] * response * response;
    lag1 += power[i] * response * response * std::cos(omega[i]);
    bias2 += (1.0 - response) * (1.0 - response) / difference[i];
    if (response < 0.5 && cutoff_ == std::numbers::pi) cutoff_ = omega[i];
  }
  noise_gain_ = std::sqrt(noise2 / kGrid);
  correlation_ = lag1 / noise2;
  resolution_ = prior_increment * std::sqrt(bias2 / kGrid);
}

double WienerLowPass::image_noise_gain() const {
  return noise_gain_ * std::sqrt((2.0 / 3.0) * (2.0 / 3.0 + correlation_ / 3.0));
}

double prior_increment(const InstrumentSpec& instrument, const Surface& surface) {
  const SpiralSpec& s = instrument.spiral;
  const std::int64_t total = s.samples();
  if (total < 2) return 0.0;
  const std::int64_t pairs = std::min<std::int64_t>(65536, total - 1);
  const double h = 1.0 / s.sample_rate, omega = s.rotation_frequency();
  const auto at = [&](std::int64_t n) {
    const double t = static_cast<double>(n) * h, r = s.start_radius + s.radial_speed * t;
    return surface.topography(r * std::cos(omega * t), r * std::sin(omega * t));
  };
  double sum = 0.0;
  for (std::int64_t j = 0; j < pairs; ++j) {
    const std::int64_t n = j * (total - 1) / pairs;
    const double d = at(n + 1) - at(n);
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(pairs));
}

double sampled_resolution(const InstrumentSpec& instrument, const Surface& surface, const WienerLowPass& filter) {
  const SpiralSpec& s = instrument.spiral;
  const std::int64_t total = s.samples(), k_max = filter.half_width();
  const std::int64_t length = std::min<std::int64_t>(2048, total);
  if (length <= 2 * k_max) return 0.0;
  const std::int64_t stretches = std::min<std::int64_t>(64, std::max<std::int64_t>(1, total / length));
  const double h = 1.0 / s.sample_rate, omega = s.rotation_frequency();
  const std::vector<double>& g = filter.taps();
  std::vector<double> f(static_cast<std::size_t>(length));
  double sum = 0.0;
  std::int64_t count = 0;
  for (std::int64_t j = 0; j < stretches; ++j) {
    const std::int64_t first = j * (total - length) / std::max<std::int64_t>(1, stretches - 1);
    for (std::int64_t i = 0; i < length; ++i) {
      const double t = static_cast<double>(first + i) * h, r = s.start_radius + s.radial_speed * t;
      f[static_cast<std::size_t>(i)] = surface(r * std::cos(omega * t), r * std::sin(omega * t));
    }
    for (std::int64_t c = k_max; c < length - k_max; ++c) {
      double v = g[0] * f[static_cast<std::size_t>(c)];
      for (std::int64_t k = 1; k <= k_max; ++k)
        v += g[static_cast<std::size_t>(k)] * (f[static_cast<std::size_t>(c - k)] + f[static_cast<std::size_t>(c + k)]);
      const double e = v - f[static_cast<std::size_t>(c)];
      sum += e * e;
      ++count;
    }
  }
  return std::sqrt(sum / static_cast<double>(count));
}

double prior_increment_floor(const PlantInverse& inverse, double noise, int harmonics, double turns_per_sample) {
  // W(ω_p) = 0.99 at ω_p = 2π (N + 1) f_rot/f_s: (σ²/A)|H|²|D|² = 1/0.99 − 1
  const double omega = std::min(std::numbers::pi, 2.0 * std::numbers::pi * (harmonics + 1) * turns_per_sample);
  return noise * std::sqrt(inverse_power(inverse, omega) * 2.0 * (1.0 - std::cos(omega)) / (1.0 / 0.99 - 1.0));
}

std::optional<WienerLowPass> noise_aware_filter(const InstrumentSpec& instrument, const Surface& surface) {
  const double noise = instrument.detector.noise;
  if (instrument.reconstruction.inverse_filter == InverseFilter::exact || !(noise > 0.0)) return std::nullopt;
  const SpiralSpec& spiral = instrument.spiral;
  const PlantInverse inverse(instrument.assumed_bandwidth(), spiral.sample_rate);
  const double stated = instrument.reconstruction.prior_increment;
  const double prior = std::max(stated > 0.0 ? stated : prior_increment(instrument, surface),
                                prior_increment_floor(inverse, noise, instrument.controller.harmonics,
                                                      spiral.spindle_frequency / spiral.sample_rate));
  WienerLowPass filter(inverse, noise, prior);
  if (filter.half_width() == 0) return std::nullopt;  // transparent: the exact inverse
  return filter;
}

}  // namespace afmkit::scan
