// The disturbance of the seed-2 loop from its samples (sampled_disturbance.hpp): period average and its discrete
// Fourier coefficients, as seed-2 eq. 14's amplitudes and phases.
#include "afmkit/control/sampled_disturbance.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::control {

namespace {
// Harmonics below this fraction of the samples' RMS are the rounding of the sums (about S·1e-16), not signal: left
// out (they would cost O(1) per simulated step each); unrepresented_rms accounts for them.
constexpr double kRounding = 1e-13;
}  // namespace

SampledDisturbance disturbance_from_samples(const std::vector<double>& samples, int samples_per_period,
                                            int max_harmonic, const char* parameter) {
  const auto s = static_cast<std::size_t>(samples_per_period);
  if (samples_per_period < 2)
    throw InvalidParameter(parameter, fmt::format("{} has {} samples per rotation period: must have at least 2",
                                                  parameter, samples_per_period));
  if (samples.empty() || samples.size() % s != 0)
    throw InvalidParameter(parameter, fmt::format("{} has {} samples: must cover whole rotation periods (a multiple "
                                                  "of the {} samples per period, at least one period)",
                                                  parameter, samples.size(), s));
  for (std::size_t j = 0; j < samples.size(); ++j)
    if (!std::isfinite(samples[j]))
      throw InvalidParameter(parameter, fmt::format("{} sample {} is {}: every sample must be finite", parameter, j,
                                                    samples[j]));
  SampledDisturbance out;
  out.samples_per_period = samples_per_period;
  out.periods = static_cast<int>(samples.size() / s);
  // the period average f̄_j (the model's f is T-periodic) and what it leaves
  std::vector<double> mean(s, 0.0);
  for (std::size_t j = 0; j < samples.size(); ++j) mean[j % s] += samples[j];
  for (double& m : mean) m /= out.periods;
  double sum2 = 0, rest2 = 0;
  for (std::size_t j = 0; j < samples.size(); ++j) {
    sum2 += samples[j] * samples[j];
    rest2 += (samples[j] - mean[j % s]) * (samples[j] - mean[j % s]);
  }
  out.rms = std::sqrt(sum2 / samples.size());
  out.non_periodic_rms = std::sqrt(rest2 / samples.size());
  // c_k = (1/S) Σ f̄_j e^{−2πikj/S}; f̄_j = c_0 + Σ_k 2|c_k| cos(kθ_j + arg c_k), θ_j = 2πj/S, so
  // F_k = 2|c_k| and φ_k = arg c_k + π/2 (eq. 14 uses sin)
  const int nyquist = (samples_per_period - 1) / 2;  // k < S/2
  out.harmonics = max_harmonic > 0 ? std::min(max_harmonic, nyquist) : nyquist;
  double c0 = 0;
  for (double m : mean) c0 += m;
  c0 /= static_cast<double>(s);
  std::vector<std::complex<double>> twiddle(s);  // e^{−2πim/S}
  for (std::size_t m = 0; m < s; ++m)
    twiddle[m] = std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(m) / static_cast<double>(s));
  std::vector<Disturbance::Harmonic> h;
  for (int k = 1; k <= out.harmonics; ++k) {
    std::complex<double> c = 0;
    const auto step = static_cast<std::size_t>(k);  // < S: index k·j mod S by one subtraction per sample
    for (std::size_t j = 0, m = 0; j < s; ++j) {
      c += mean[j] * twiddle[m];
      m += step;
      if (m >= s) m -= s;
    }
    c /= static_cast<double>(s);
    const double amplitude = 2.0 * std::abs(c);
    if (amplitude > kRounding * out.rms) h.push_back({k, amplitude, std::arg(c) + std::numbers::pi / 2});
  }
  out.disturbance = Disturbance(c0, std::move(h));
  double miss2 = 0;
  for (std::size_t j = 0; j < s; ++j) {
    const double d = mean[j] - out.disturbance(2.0 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(s));
    miss2 += d * d;
  }
  out.unrepresented_rms = std::sqrt(miss2 / static_cast<double>(s));
  return out;
}

}  // namespace afmkit::control
