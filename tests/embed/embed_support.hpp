#pragma once
// Shared by the embed tests: a reference design and the disturbance with known harmonics.
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "afmkit/embed/design.hpp"

namespace embed_test {

constexpr int kSamplesPerTurn = 100;  // f_s / (Ω/2π): an integer number of samples per turn

/// 50 Hz spindle, f_s = 5 kHz, N = 10, α = 0.1 Ω, β = −0.1 Ω, K = γ = 20 Ω, static plant, τ = 0.
inline afmkit::embed::ExportSpec reference_spec(afmkit::embed::Precision p, int harmonics = 10) {
  afmkit::embed::ExportSpec s;
  s.rotation_frequency = 2.0 * std::numbers::pi * 50.0;
  s.sample_rate = 50.0 * kSamplesPerTurn;
  s.harmonics = harmonics;
  s.alpha = 0.1 * s.rotation_frequency;
  s.beta = -0.1 * s.rotation_frequency;
  s.gain = 20.0 * s.rotation_frequency;
  s.plant_rate = s.gain;
  s.delay = 0.0;
  s.precision = p;
  return s;
}

/// Disturbance d_n = c0 + Σ_{k=1..N} Re(D_k e^{ikθ_n}), θ_n = 2π n / kSamplesPerTurn (phase from n mod turn: exact).
struct Disturbance {
  double offset = 0.2;
  std::vector<std::complex<double>> d;  // D_k, k = 1..N (index k − 1)
  explicit Disturbance(int n) {
    for (int k = 1; k <= n; ++k) {
      const double amp = k == 1 ? 1.0 : 0.5 / k, phase = k == 1 ? 0.0 : 2.399963229728653 * k;
      d.push_back(std::polar(amp, phase));
    }
  }
  double at(long long n) const {
    const double theta = 2.0 * std::numbers::pi * static_cast<double>(n % kSamplesPerTurn) / kSamplesPerTurn;
    double v = offset;
    for (std::size_t k = 1; k <= d.size(); ++k) v += (d[k - 1] * std::polar(1.0, static_cast<double>(k) * theta)).real();
    return v;
  }
};

/// Complex amplitude C_k of Re(C_k e^{ikθ}) in samples x_0 … over whole turns (x starts at a turn boundary);
/// the DFT over whole turns (independent of the filter).
inline std::complex<double> harmonic(const std::vector<double>& x, int k) {
  std::complex<double> acc = 0.0;
  for (std::size_t n = 0; n < x.size(); ++n) {
    const double theta = 2.0 * std::numbers::pi * static_cast<double>(n % kSamplesPerTurn) / kSamplesPerTurn;
    acc += x[n] * std::polar(1.0, -k * theta);
  }
  return (k == 0 ? 1.0 : 2.0) * acc / static_cast<double>(x.size());
}

}  // namespace embed_test
