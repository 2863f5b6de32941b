// The inverse reconstruction of the rotational scanner's topography (plant_inverse.hpp, docs/scan.md#reconstruction):
// the discrete inverse undoes the plant exactly, an ideal instrument images the truth, a wrong assumed plant rate
// costs what the first-order sensitivity says, and the lagged reconstruction is the truth turned by atan(Ω/γ).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/levelling.hpp"
#include "afmkit/scan/plant_inverse.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/scan/turn_metrics.hpp"
#include "afmkit/scan/virtual_scan.hpp"

namespace {
using namespace afmkit::scan;
constexpr double kInversePi = std::numbers::pi;

// y(t) of ẏ = −γ (y − f), f ramping linearly from f0 to f1 over [0, h], by 4000 classical Runge–Kutta steps: an
// integration independent of the closed form the simulator and the inverse use.
double lag_over_interval(double y, double f0, double f1, double gamma, double h) {
  const int steps = 4000;
  const double dt = h / steps;
  const auto rhs = [&](double t, double v) { return -gamma * (v - (f0 + (f1 - f0) * t / h)); };
  for (int k = 0; k < steps; ++k) {
    const double t = k * dt;
    const double k1 = rhs(t, y), k2 = rhs(t + dt / 2, y + dt / 2 * k1), k3 = rhs(t + dt / 2, y + dt / 2 * k2),
                 k4 = rhs(t + dt, y + dt * k3);
    y += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return y;
}

TEST(PlantInverseRecursion, UndoesTheFirstOrderLagOfARampedSignal) {
  for (const double gamma_h : {1e-4, 9.9e-3, 1.01e-2, 0.1256, 2.0}) {  // both sides of the series/closed-form switch
    const double fs = 1e4, gamma = gamma_h * fs, h = 1 / fs;
    std::mt19937_64 rng(7);
    std::normal_distribution<double> heights(0.0, 1e-8);
    std::vector<double> f(60);
    for (double& v : f) v = heights(rng);
    PlantInverse inverse(gamma, fs);
    double y = f[0], worst = 0;
    EXPECT_EQ(inverse.step(y), f[0]);  // settled start: y = f
    for (std::size_t n = 1; n < f.size(); ++n) {
      y = lag_over_interval(y, f[n - 1], f[n], gamma, h);
      worst = std::max(worst, std::abs(inverse.step(y) - f[n]));
    }
    // RK4's error (dt⁴-small) amplified by the inverse's gain at most ~1/b1² ≈ 4/(γh)²
    EXPECT_LT(worst, 1e-8 * 1e-6 / std::min(1.0, gamma_h * gamma_h)) << "gamma h = " << gamma_h;
    EXPECT_GT(inverse.pole(), -1.0);
    EXPECT_LT(inverse.pole(), 0.0);
  }
}

TEST(PlantInverseRecursion, NoiseGainIsTheRootSumOfSquaresOfTheImpulseResponse) {
  // the impulse response of f̂ = (w_{n+1} − a w_n − b0 f̂_n)/b1 by the recursion written out here, against the
  // closed form G² = (1 + (p − a)²/(1 − p²))/b1²
  const PlantInverse model(2 * kInversePi * 1000, 50e3);
  const double a = model.decay(), b0 = model.b0(), b1 = model.b1();
  double previous_w = 0, previous_f = 0, sum = 0;
  for (int n = 0; n < 200000; ++n) {
    const double w = n == 0 ? 1.0 : 0.0;
    const double f = (w - a * previous_w - b0 * previous_f) / b1;
    sum += f * f;
    previous_w = w;
    previous_f = f;
  }
  EXPECT_NEAR(model.noise_gain(), std::sqrt(sum), 1e-9 * std::sqrt(sum));
  {  // ρ1 from the same impulse response
    double lag1 = 0, prev_w = 0, prev_f = 0, before = 0;
    for (int n = 0; n < 200000; ++n) {
      const double w = n == 0 ? 1.0 : 0.0;
      const double f = (w - a * prev_w - b0 * prev_f) / b1;
      if (n > 0) lag1 += before * f;
      before = f;
      prev_w = w;
      prev_f = f;
    }
    EXPECT_NEAR(model.noise_correlation(), lag1 / sum, 1e-9);
  }
  EXPECT_GT(model.noise_gain(), 100.0);  // the price of undoing a lag of γh = 0.126 from samples
  // b0 + b1 = 1 − a (a constant height passes unchanged)
  EXPECT_NEAR(b0 + b1, 1 - a, 1e-15);
}

TEST(PlantInverseRecursion, WhiteNoiseComesOutMultipliedByTheNoiseGain) {
  // w = the exact lag of a slow sinusoid + white noise σ: RMS(f̂ − f) = G σ (the budget's noise term), checked on
  // 200 000 samples (statistical spread ≈ 1/√(effective samples) ≈ 1 %)
  const double fs = 50e3, gamma = 2 * kInversePi * 1000, h = 1 / fs, sigma = 1e-10;
  PlantInverse inverse(gamma, fs);
  const double x = gamma * h, a = std::exp(-x), m = -std::expm1(-x) / x, b0 = m - a, b1 = 1 - m;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, sigma);
  const auto f = [&](long n) { return 2e-8 * std::sin(2 * kInversePi * 37.0 * static_cast<double>(n) * h); };
  double w = f(0), sum = 0;
  long count = 0;
  inverse.step(w);
  for (long n = 1; n < 200000; ++n) {
    w = a * w + b0 * f(n - 1) + b1 * f(n);  // the lag without noise (the recursion the inverse undoes)
    const double e = inverse.step(w + noise(rng)) - f(n);
    if (n > 1000) {
      sum += e * e;
      ++count;
    }
  }
  EXPECT_NEAR(std::sqrt(sum / static_cast<double>(count)) / (inverse.noise_gain() * sigma), 1.0, 0.05);
}

TEST(PlantInverseRecursion, RestartsAfterAGapAndReportsTheSettlingSamplesAsMissing) {
  PlantInverse inverse(2 * kInversePi * 1000, 50e3);
  EXPECT_EQ(inverse.step(3e-9), 3e-9);
  EXPECT_NEAR(inverse.step(3e-9), 3e-9, 1e-23);  // a constant height passes (b0 + b1 = 1 − a), to rounding
  EXPECT_TRUE(std::isnan(inverse.step(std::numeric_limits<double>::quiet_NaN())));
  const std::int64_t settle = inverse.settle_samples();
  // |p|^settle <= 1 % < |p|^(settle − 1)
  const double p = std::abs(inverse.pole());
  EXPECT_LE(std::pow(p, static_cast<double>(settle)), 0.01);
  EXPECT_GT(std::pow(p, static_cast<double>(settle - 1)), 0.01);
  for (std::int64_t k = 0; k <= settle; ++k) EXPECT_TRUE(std::isnan(inverse.step(3e-9))) << k;
  EXPECT_NEAR(inverse.step(3e-9), 3e-9, 1e-23);
  EXPECT_THROW(PlantInverse(0.0, 50e3), afmkit::InvalidParameter);
}

TEST(PlantInverseRecursion, RestartsOnARampFromTheIntervalMeanNotTheLaggedValue) {
  // f ramps by c per sample; w is its exact lag (lag error c/(γh) ≈ 8c at γh = 0.126). After a gap the restart
  // error is the interval mean's ≈ c/2, so the first sample shown (after settle_samples) is within 1 % of that;
  // a restart from w would leave 1 % of 8c
  const double fs = 50e3, gamma = 2 * kInversePi * 1000, c = 1e-9;
  PlantInverse inverse(gamma, fs);
  const double x = gamma / fs, a = std::exp(-x), m = -std::expm1(-x) / x, b0 = m - a, b1 = 1 - m;
  const auto f = [&](long n) { return c * static_cast<double>(n); };
  double w = f(0);
  inverse.step(w);
  long shown = -1;
  double error = 0;
  for (long n = 1; n < 2000 && shown < 0; ++n) {
    w = a * w + b0 * f(n - 1) + b1 * f(n);
    const double out = inverse.step(n >= 500 && n < 510 ? std::numeric_limits<double>::quiet_NaN() : w);
    if (n >= 510 && std::isfinite(out)) {
      shown = n;
      error = std::abs(out - f(n));
    }
  }
  EXPECT_EQ(shown, 510 + inverse.settle_samples() + 1);
  EXPECT_LT(error, 0.01 * 0.6 * c);
  EXPECT_GT(0.01 * c / x, 10 * 0.01 * 0.6 * c);  // what a restart from w would leave: 13 times more
}

// 50 Hz, 400 samples per turn, a 2 mm disc at 20 µm pitch: 100 turns, 40 000 samples; images of 64² pixels.
InstrumentSpec inverse_test_scan() {
  InstrumentSpec s;
  s.spiral.sample_rate = 20e3;
  s.spiral.end_radius = 2e-3;
  s.spiral.radial_speed = 1e-3;
  return s;
}

Surface inverse_test_rough(double tilt_deg) {
  const double half = 2.05e-3;
  const Grid g{512, 512, 2 * half, 2 * half, -half, -half};
  return Surface(rough(g, RoughSpec{20e-9, 400e-6, 5}), Tilt(tilt_deg * kInversePi / 180, 0.7));
}

TEST(InverseReconstruction, AnIdealInstrumentImagesTheTruth) {
  // no noise, the plant known exactly, controller on (tilt removed from the deflection): the inverse reconstruction
  // is the true height at every sample, so its image differs from the truth only by the imaging (the same
  // interpolation applied to the true heights), and stays within 1 % of the sample's RMS height
  const InstrumentSpec s = inverse_test_scan();
  ASSERT_EQ(s.reconstruction.method, Reconstruction::inverse);  // the default
  const Surface surface = inverse_test_rough(0.05);
  const VirtualScan v = run_virtual_scan(s, surface, image_grid(s, 64));
  ASSERT_EQ(v.method, Reconstruction::inverse);
  EXPECT_LT(v.budget.reconstruction, 1e-9 * v.sample_rms_height);
  EXPECT_NEAR(v.inverse_rms_error, v.budget.imaging, 1e-9 * v.sample_rms_height);
  EXPECT_LT(v.topography_rms_error, 0.01 * v.sample_rms_height);
  EXPECT_EQ(v.topography_rms_error, v.inverse_rms_error);
  // the lagged image carries the plant's lag: tens of per cent here
  EXPECT_GT(v.lagged_rms_error, 0.1 * v.sample_rms_height);
  EXPECT_EQ(v.lagged_rms_error, levelled_rms_difference(v.alternative, v.truth));
  EXPECT_NEAR(v.sample_rms_height, 20e-9, 4e-9);

  // the lagged reconstruction chosen: the images swap, the errors do not change
  InstrumentSpec lagged = s;
  lagged.reconstruction.method = Reconstruction::lagged;
  const VirtualScan l = run_virtual_scan(lagged, surface, image_grid(s, 64));
  EXPECT_EQ(l.topography_rms_error, v.lagged_rms_error);
  EXPECT_EQ(l.inverse_rms_error, v.inverse_rms_error);
}

// (1/γ̂ − 1/γ) ḟ at the pixel centres, ḟ = Ω ∂S/∂θ + v_r ∂S/∂r by central differences of the surface itself.
HeightMap first_order_mismatch_error(const VirtualScan& v, const Surface& surface, const InstrumentSpec& s,
                                     double gamma_hat) {
  const HeightMap& image = v.topography;
  const Grid& g = image.grid();
  const double omega = s.spiral.rotation_frequency(), vr = s.spiral.radial_speed, gamma = s.plant.bandwidth;
  const double dtheta = 2e-3, dr = 2e-6;
  std::vector<double> z(image.size(), 0.0);
  std::vector<std::uint8_t> valid(image.size(), 0);
  for (long j = 0; j < g.y_resolution; ++j)
    for (long i = 0; i < g.x_resolution; ++i) {
      if (!image.valid(i, j)) continue;
      const double x = g.x_offset + (i + 0.5) * image.dx(), y = g.y_offset + (j + 0.5) * image.dy();
      const double r = std::hypot(x, y), th = std::atan2(y, x);
      const auto at = [&](double rr, double tt) { return surface(rr * std::cos(tt), rr * std::sin(tt)); };
      const double d_theta = (at(r, th + dtheta) - at(r, th - dtheta)) / (2 * dtheta);
      const double d_r = (at(r + dr, th) - at(std::max(r - dr, 0.0), th)) / (r + dr - std::max(r - dr, 0.0));
      const auto k = static_cast<std::size_t>(j * g.x_resolution + i);
      z[k] = (1 / gamma_hat - 1 / gamma) * (omega * d_theta + vr * d_r);
      valid[k] = 1;
    }
  return HeightMap(g, std::move(z), "m", std::move(valid));
}

TEST(InverseReconstruction, AWrongPlantRateCostsWhatTheFirstOrderSensitivitySays) {
  // f̂ − f = (1/γ̂ − 1/γ) ḟ to first order (ω ≪ γ): checked against that field computed from the surface alone, and
  // the budget's own estimate |γ/γ̂ − 1| × (lagged error) against the measured reconstruction error
  InstrumentSpec s = inverse_test_scan();
  s.controller.enabled = false;
  const Surface surface = inverse_test_rough(0.0);
  double previous = 0;
  for (const double ratio : {1.02, 1.05, 0.95}) {
    s.reconstruction.assumed_bandwidth = ratio * s.plant.bandwidth;
    const VirtualScan v = run_virtual_scan(s, surface, image_grid(s, 64));
    const HeightMap predicted = first_order_mismatch_error(v, surface, s, s.reconstruction.assumed_bandwidth);
    HeightMap zero(predicted.grid(), std::vector<double>(predicted.size(), 0.0), "m", std::vector<std::uint8_t>(
        predicted.size(), 1));
    const double independent = levelled_rms_difference(predicted, zero);
    EXPECT_NEAR(v.budget.reconstruction / independent, 1.0, 0.15) << "ratio " << ratio;
    EXPECT_NEAR(v.budget.plant / v.budget.reconstruction, 1.0, 0.15) << "ratio " << ratio;
    EXPECT_NEAR(v.budget.plant_mismatch, ratio - 1, 1e-12);
    if (ratio == 1.05) {
      EXPECT_GT(v.budget.reconstruction, 2 * previous);  // grows with the mismatch
    }
    previous = v.budget.reconstruction;
    // the total is the imaging floor and the mismatch term added in quadrature
    EXPECT_NEAR(v.inverse_rms_error / v.budget.predicted, 1.0, 0.15);
  }
}

TEST(InverseReconstruction, DetectorNoiseCostsTheImageNoiseGainTimesSigma) {
  // the budget's noise term G √((2/3)(2/3 + ρ1/3)) σ_d (closed form) against the measured reconstruction error
  // (inverse image minus the imaged true heights), for two noise levels: the error scales with σ_d
  InstrumentSpec s = inverse_test_scan();
  s.reconstruction.inverse_filter = InverseFilter::exact;  // the Wiener low-pass: test_wiener_inverse.cpp
  const Surface surface = inverse_test_rough(0.05);
  for (const double sigma : {1e-11, 1e-10}) {
    s.detector.noise = sigma;
    const VirtualScan v = run_virtual_scan(s, surface, image_grid(s, 64));
    const PlantInverse model(s.plant.bandwidth, s.spiral.sample_rate);
    EXPECT_DOUBLE_EQ(v.budget.noise, model.image_noise_gain() * sigma);
    EXPECT_NEAR(v.budget.reconstruction / v.budget.noise, 1.0, 0.1) << "sigma " << sigma;
    // G at the samples is larger: the imaging averages neighbouring samples whose noise alternates in sign
    EXPECT_LT(model.image_noise_gain(), 0.6 * model.noise_gain());
  }
}

TEST(InverseReconstruction, TheLaggedImageIsTheTruthTurnedByTheLagAngle) {
  // a tilted flat sample: the tilt's first harmonic passes the plant with gain cos φ and phase lag φ = atan(Ω/γ),
  // so the lagged image is the tilt plane turned by φ in the direction of rotation and scaled by cos φ; the
  // inverse image is the tilt plane itself
  InstrumentSpec s = inverse_test_scan();
  s.controller.enabled = false;
  s.plant.bandwidth = 2 * kInversePi * 200;  // φ = atan(50/200) = 14°: a turn well resolved
  const double half = 2.4e-3, azimuth = 0.4;
  const Surface surface(flat(Grid{16, 16, 2 * half, 2 * half, -half, -half}), Tilt(0.01 * kInversePi / 180, azimuth));
  const VirtualScan v = run_virtual_scan(s, surface, image_grid(s, 64));
  const double phi = std::atan(s.spiral.rotation_frequency() / s.plant.bandwidth);
  const Plane lagged = fit_plane(v.alternative), inverted = fit_plane(v.topography);
  const double slope = surface.tilt().slope();
  // the plane's gradient direction is the tilt azimuth; its length the slope
  EXPECT_NEAR(std::atan2(lagged.c, lagged.b) - azimuth, phi, 0.01 * phi);
  EXPECT_NEAR(std::hypot(lagged.b, lagged.c) / slope, std::cos(phi), 0.01);
  EXPECT_NEAR(std::atan2(inverted.c, inverted.b), azimuth, 1e-3 * phi);
  EXPECT_NEAR(std::hypot(inverted.b, inverted.c) / slope, 1.0, 1e-3);
}

// The per-turn first harmonics (turn_metrics.hpp) take cos θ, sin θ from a rotation recurrence: over 400 turns of
// 2000 samples, uniform or with a jittered step, the amplitudes of a known first harmonic are exact to rounding.
TEST(InverseReconstructionTurnMetrics, FirstHarmonicsStayExactOverLongUniformAndJitteredSpirals) {
  for (const bool jitter : {false, true}) {
    std::vector<TurnRecord> turns;
    TurnMetrics metrics(0.0, [&](const TurnRecord& r) { turns.push_back(r); });
    const double a = 3e-6, b = 1e-9, phase = 0.3, step = 2 * kInversePi / 2000;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> wobble(0.5, 1.5);
    double theta = 0;
    for (std::int64_t n = 0; n < 800000; ++n) {
      const ScanSample s{n, 0.0, theta, 1e-3, a * std::cos(theta - phase) + 2e-9, b * std::sin(theta) - 1e-9, 0, 0,
                         0, 0, false};
      metrics.sample(s);
      if (!jitter)
        theta = static_cast<double>(n + 1) * step;  // as the simulator: θ = Ω t_n
      else
        theta += n % 1000 == 0 ? step * wobble(rng) : step;  // a step that changes now and then
    }
    ASSERT_GE(turns.size(), 390u);
    double worst_a = 0, worst_b = 0;
    for (const TurnRecord& r : turns) {
      worst_a = std::max(worst_a, std::abs(r.surface_first_harmonic / a - 1));
      worst_b = std::max(worst_b, std::abs(r.deflection_first_harmonic / b - 1));
    }
    EXPECT_LT(worst_a, 1e-9) << "jitter " << jitter;
    EXPECT_LT(worst_b, 1e-9) << "jitter " << jitter;
  }
}

}  // namespace
