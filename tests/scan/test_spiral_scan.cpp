// The spiral-scan simulation against independent computations: the frequency response of the plant (seed-2 eq. 1)
// in closed form, superposition (the reconstruction is exactly the uncontrolled deflection), the internal-model
// principle (the controller removes harmonic 1 and keeps harmonic 2), the saturation radius from the steady-state
// amplitude.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/scan/spiral_scan.hpp"
#include "afmkit/scan/turn_metrics.hpp"

namespace {
using namespace afmkit::scan;

Surface flat_tilted(double half_size, double tilt_deg, double azimuth_deg = 0.0) {
  const Grid g{64, 64, 2 * half_size, 2 * half_size, -half_size, -half_size};
  return Surface(flat(g), Tilt(tilt_deg * std::numbers::pi / 180, azimuth_deg * std::numbers::pi / 180));
}

// A small, fast instrument: 50 Hz, 400 samples per turn, a ring of radii (slow radial speed).
InstrumentSpec ring(double r0, double r1, double turns) {
  InstrumentSpec s;
  s.spiral.spindle_frequency = 50.0;
  s.spiral.sample_rate = 20e3;
  s.spiral.start_radius = r0;
  s.spiral.end_radius = r1;
  s.spiral.radial_speed = (r1 - r0) * 50.0 / turns;
  return s;
}

struct SpiralRecorder final : ScanObserver {
  std::vector<ScanSample> samples;
  bool sample(const ScanSample& s) override {
    samples.push_back(s);
    return true;
  }
};

// Complex amplitude of harmonic k of `value` over the samples of turn `turn` (DFT over whole turns: the samples per
// turn are an integer in these tests).
template <class F>
std::complex<double> harmonic(const std::vector<ScanSample>& v, long turn, int k, F value) {
  std::complex<double> sum = 0;
  long n = 0;
  for (const ScanSample& s : v)
    if (static_cast<long>(std::floor(s.angle / (2 * std::numbers::pi) + 1e-9)) == turn) {
      sum += value(s) * std::exp(std::complex<double>(0, -k * s.angle));
      ++n;
    }
  return 2.0 * sum / static_cast<double>(n);
}

TEST(SpiralScan, UncontrolledDeflectionIsTheTiltThroughThePlantResponse) {
  // eq. 1 without control: y follows f through γ/(γ + iΩ); the tilt's first harmonic has amplitude r tan ψ.
  InstrumentSpec s = ring(1e-3, 1e-3 + 1e-9, 40);
  s.controller.enabled = false;
  const Surface surface = flat_tilted(2e-3, 0.05);
  std::vector<TurnRecord> turns;
  TurnMetrics metrics(surface.tilt().slope(), [&](const TurnRecord& r) { turns.push_back(r); });
  simulate_scan(s, surface, metrics);
  ASSERT_GE(turns.size(), 30u);
  const double omega = s.spiral.rotation_frequency(), gamma = s.plant.bandwidth;
  const double expected = 1e-3 * std::tan(0.05 * std::numbers::pi / 180) * gamma / std::hypot(gamma, omega);
  // ZOH of f over h = 50 µs: the response is γ/(γ+iΩ) e^{−iΩh/2} sinc-like to O((Ωh)²) ≈ 2e-4
  EXPECT_NEAR(turns.back().deflection_first_harmonic / expected, 1.0, 3e-4);
  EXPECT_NEAR(turns.back().surface_first_harmonic / (turns.back().radius * surface.tilt().slope()), 1.0, 1e-9);
  EXPECT_NEAR(turns.back().tilt_first_harmonic, turns.back().surface_first_harmonic, 1e-9 * turns.back().tilt_first_harmonic);
}

TEST(SpiralScan, ReconstructionEqualsTheUncontrolledDeflectionAndGainErrorShowsExactly) {
  // Superposition: y_on = L[f] + L[(1+ε) u(t − τ)], ŷ_u = L[u(t − τ)] with the same exact steps, so
  // d − ŷ_u = y_off + ε ŷ_u sample by sample (τ = 1.37 samples: the split interval is exercised).
  InstrumentSpec s = ring(1e-3, 1.2e-3, 30);
  s.plant.delay = 1.37 / s.spiral.sample_rate;
  const Surface surface = flat_tilted(2e-3, 0.05, 30);
  InstrumentSpec off = s;
  off.controller.enabled = false;
  for (double eps : {0.0, 0.1}) {
    s.plant.gain_error = eps;
    SpiralRecorder on, reference;
    simulate_scan(s, surface, on);
    simulate_scan(off, surface, reference);
    ASSERT_EQ(on.samples.size(), reference.samples.size());
    double worst = 0, scale = 0, actuator = 0;
    for (std::size_t i = 0; i < on.samples.size(); ++i) {
      const double predicted = reference.samples[i].deflection - eps * on.samples[i].actuator;  // z_a = −ŷ_u
      worst = std::max(worst, std::abs(on.samples[i].topography - predicted));
      scale = std::max(scale, std::abs(reference.samples[i].deflection));
      actuator = std::max(actuator, std::abs(on.samples[i].actuator));
    }
    EXPECT_LT(worst, 1e-12 * scale) << "gain error " << eps;
    EXPECT_GT(actuator, 0.5 * scale);  // the controller did move the actuator
  }
}

TEST(SpiralScan, ControllerRemovesTheFirstHarmonicAndKeepsTheSecond) {
  // A saddle z = c (x² − y²)/R = c r² cos 2θ / R adds a pure second harmonic at fixed r; the tilt a first.
  // Internal model: harmonic 1 of y → 0; harmonic 2 = γ/(γ + 2iΩ) × (c r²/R), as without control.
  const double r = 1e-3, half = 2e-3, c = 40e-9;
  const long n = 257;
  std::vector<double> z(n * n);
  const Grid g{n, n, 2 * half, 2 * half, -half, -half};
  for (long j = 0; j < n; ++j)
    for (long i = 0; i < n; ++i) {
      const double x = -half + (i + 0.5) * 2 * half / n, y = -half + (j + 0.5) * 2 * half / n;
      z[j * n + i] = c * (x * x - y * y) / half;
    }
  // bilinear interpolation of a quadratic is exact up to dx²/4 · |∂²z| = c dx²/(2 half) ≈ 5e-15 m: negligible
  const Surface surface(HeightMap(g, z), Tilt(0.05 * std::numbers::pi / 180, 0.0));
  InstrumentSpec s = ring(r, r + 1e-12, 60);
  SpiralRecorder rec;
  simulate_scan(s, surface, rec);
  const long last = 58;
  const auto y = [](const ScanSample& v) { return v.deflection; };
  const double omega = s.spiral.rotation_frequency(), gamma = s.plant.bandwidth;
  const double tilt = r * surface.tilt().slope();
  EXPECT_LT(std::abs(harmonic(rec.samples, last, 1, y)), 1e-6 * tilt);
  const double second = std::abs(harmonic(rec.samples, last, 2, y));
  const double expected = gamma / std::hypot(gamma, 2 * omega) * c * r * r / half;
  EXPECT_NEAR(second / expected, 1.0, 1e-3);
}

TEST(SpiralScan, UncontrolledScanSaturatesWhereTheSteadyAmplitudeReachesTheRange) {
  // |y_1| = r tan ψ γ/√(γ² + Ω²) reaches R_d at r = R_d √(γ² + Ω²)/(γ tan ψ) (flat sample, noise-free).
  InstrumentSpec s = ring(0.5e-3, 4e-3, 200);
  s.controller.enabled = false;
  const Surface surface = flat_tilted(4.1e-3, 0.05);
  struct Stop final : ScanObserver {
    bool sample(const ScanSample& v) override { return !v.saturated; }
  } stop;
  const ScanRun run = simulate_scan(s, surface, stop);
  EXPECT_TRUE(run.stopped_early);
  const double omega = s.spiral.rotation_frequency(), gamma = s.plant.bandwidth;
  const double expected = s.detector.range * std::hypot(gamma, omega) / (gamma * surface.tilt().slope());
  EXPECT_NEAR(run.first_saturation_radius, expected, 1.5 * s.spiral.pitch());
  EXPECT_EQ(run.saturated_samples, 1);

  // with the controller the same scan never saturates
  s.controller.enabled = true;
  struct Count final : ScanObserver {
    bool sample(const ScanSample&) override { return true; }
  } count;
  const ScanRun controlled = simulate_scan(s, surface, count);
  EXPECT_EQ(controlled.saturated_samples, 0);
  EXPECT_EQ(controlled.samples, s.spiral.samples());
}

TEST(SpiralScan, NoiseHasTheRequestedRmsAndIsReproducible) {
  InstrumentSpec s = ring(1e-3, 1e-3 + 1e-12, 20);
  s.controller.enabled = false;
  s.detector.noise = 1e-9;
  const Surface surface = flat_tilted(2e-3, 0.0);
  SpiralRecorder a, b;
  simulate_scan(s, surface, a);
  simulate_scan(s, surface, b);
  double sum = 0;
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    sum += a.samples[i].deflection * a.samples[i].deflection;
    ASSERT_EQ(a.samples[i].deflection, b.samples[i].deflection);
  }
  const double rms = std::sqrt(sum / a.samples.size());
  EXPECT_NEAR(rms / 1e-9, 1.0, 0.02);  // 8000 samples: relative standard error 1/√(2·8000) ≈ 0.008
}

TEST(SpiralScan, BadInstrumentIsNamed) {
  const Surface surface = flat_tilted(2e-3, 0.05);
  SpiralRecorder rec;
  const auto param = [&](InstrumentSpec s) {
    try {
      simulate_scan(s, surface, rec);
    } catch (const afmkit::InvalidParameter& e) {
      return e.parameter();
    }
    return std::string("none");
  };
  InstrumentSpec s = ring(1e-3, 1.1e-3, 5);
  auto t = s;
  t.plant.delay = 0.02;  // one period at 50 Hz
  EXPECT_EQ(param(t), "delay");
  t = s;
  t.plant.bandwidth = -1;
  EXPECT_EQ(param(t), "bandwidth");
  t = s;
  t.controller.harmonics = 250;  // 250 × 50 Hz = 12.5 kHz > f_s/2 = 10 kHz
  EXPECT_EQ(param(t), "harmonics");
  t = s;
  t.spiral.end_radius = 0.5e-3;
  EXPECT_EQ(param(t), "end_radius");
  t = s;
  t.detector.range = std::nan("");
  EXPECT_EQ(param(t), "detector_range");
  t = s;
  t.plant.gain_error = -1.0;
  EXPECT_EQ(param(t), "gain_error");
  t = s;
  t.spiral.sample_rate = 100;  // 2 samples per turn
  EXPECT_EQ(param(t), "sample_rate");
  EXPECT_TRUE(rec.samples.empty());
  EXPECT_THROW(Tilt(std::numbers::pi / 2, 0.0), afmkit::InvalidParameter);
}

}  // namespace
