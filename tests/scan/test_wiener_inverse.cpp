// The noise-aware plant inverse (wiener_inverse.hpp, docs/scan.md#noise-aware-inverse): its closed-form budget
// (noise gain, correlation, resolution) against direct simulations, the streamed low-pass against a convolution
// written out here, the exact inverse unchanged without noise, and a noisy scan imaged far better than by the exact
// inverse or the lagged reconstruction.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

#include "afmkit/scan/levelling.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/scan/virtual_scan.hpp"
#include "afmkit/scan/wiener_inverse.hpp"

namespace {
using namespace afmkit::scan;

// f = Σ_k g_|k| x_{c+k} over the taps, renormalised over the finite samples inside [0, n) (as wiener_inverse.hpp
// states), written out independently of the streaming implementation.
std::vector<double> wiener_test_convolve(const std::vector<double>& x, const std::vector<double>& g) {
  const auto n = static_cast<long>(x.size()), k_max = static_cast<long>(g.size()) - 1;
  std::vector<double> out(x.size(), std::nan(""));
  for (long c = 0; c < n; ++c) {
    if (!std::isfinite(x[static_cast<std::size_t>(c)])) continue;
    double sum = 0, weights = 0;
    for (long k = -k_max; k <= k_max; ++k) {
      const long j = c + k;
      if (j < 0 || j >= n || !std::isfinite(x[static_cast<std::size_t>(j)])) continue;
      sum += g[static_cast<std::size_t>(std::abs(k))] * x[static_cast<std::size_t>(j)];
      weights += g[static_cast<std::size_t>(std::abs(k))];
    }
    if (weights >= 0.5) out[static_cast<std::size_t>(c)] = sum / weights;
  }
  return out;
}

TEST(WienerInverseBudget, NoiseGainAndCorrelationMatchWhiteNoiseThroughTheInverseAndTheTaps) {
  // w = white noise σ (f = 0): the exact inverse then the taps; RMS / σ against G_W, lag-1 correlation against ρ1,
  // on 2·10⁵ samples, at the defaults of `afmkit scan` (γh = 0.021) and at 50 kHz
  for (const double fs : {300e3, 50e3}) {
    const double gamma = 2 * std::numbers::pi * 1000, sigma = 1e-10;
    const PlantInverse model(gamma, fs);
    const WienerLowPass filter(model, sigma, 1.9e-9);
    ASSERT_GT(filter.half_width(), 2);
    PlantInverse inverse(gamma, fs);
    std::mt19937_64 rng(11);
    std::normal_distribution<double> noise(0.0, sigma);
    std::vector<double> raw(200000);
    for (double& v : raw) v = inverse.step(noise(rng));
    const std::vector<double> out = wiener_test_convolve(raw, filter.taps());
    double sum2 = 0, lag1 = 0;
    long count = 0;
    for (std::size_t n = 2000; n + 2000 < out.size(); ++n) {
      sum2 += out[n] * out[n];
      lag1 += out[n] * out[n + 1];
      ++count;
    }
    EXPECT_NEAR(std::sqrt(sum2 / count) / (filter.noise_gain() * sigma), 1.0, 0.03) << fs;
    EXPECT_NEAR(lag1 / sum2, filter.noise_correlation(), 0.02) << fs;
    // far below the exact inverse's gain, which the low-pass cuts near the Nyquist frequency
    EXPECT_LT(filter.noise_gain(), 0.05 * model.noise_gain()) << fs;
    EXPECT_LT(filter.image_noise_gain(), filter.noise_gain());
  }
}

TEST(WienerInverseBudget, ResolutionIsTheHeightTheTapsRemoveFromASampleOfThePrior) {
  // f: a random walk with increments of RMS √A (the prior itself); RMS(g * f − f) against resolution()
  const double fs = 300e3, gamma = 2 * std::numbers::pi * 1000, root_a = 2e-9;
  const WienerLowPass filter(PlantInverse(gamma, fs), 1e-10, root_a);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> step(0.0, root_a);
  std::vector<double> f(200000);
  double walk = 0;
  for (double& v : f) v = walk += step(rng);
  const std::vector<double> smooth = wiener_test_convolve(f, filter.taps());
  double sum2 = 0;
  long count = 0;
  for (std::size_t n = 2000; n + 2000 < f.size(); ++n) {
    sum2 += (smooth[n] - f[n]) * (smooth[n] - f[n]);
    ++count;
  }
  EXPECT_NEAR(std::sqrt(sum2 / count) / filter.resolution(), 1.0, 0.03);
  // the taps sum to 1 (a plane passes) and the response is ½ at the cutoff, between 0 and π
  double total = filter.taps()[0];
  for (std::size_t k = 1; k < filter.taps().size(); ++k) total += 2 * filter.taps()[k];
  EXPECT_NEAR(total, 1.0, 1e-14);
  double at_cutoff = filter.taps()[0];
  for (std::size_t k = 1; k < filter.taps().size(); ++k)
    at_cutoff += 2 * filter.taps()[k] * std::cos(static_cast<double>(k) * filter.cutoff());
  EXPECT_NEAR(at_cutoff, 0.5, 0.01);
  EXPECT_GT(filter.cutoff(), 0.1);
  EXPECT_LT(filter.cutoff(), 3.0);
}

TEST(WienerInverseBudget, MoreNoiseOrASmootherPriorLowersTheCutoffAndVanishingNoiseLeavesTheExactInverse) {
  const PlantInverse model(2 * std::numbers::pi * 1000, 300e3);
  const WienerLowPass base(model, 1e-10, 2e-9), noisier(model, 4e-10, 2e-9), smoother(model, 1e-10, 0.5e-9);
  EXPECT_LT(noisier.cutoff(), base.cutoff());
  EXPECT_LT(smoother.cutoff(), base.cutoff());
  // the cutoff ≈ (A (γh)²/σ²)^{1/4}: 16× σ²/A halves it
  EXPECT_NEAR(noisier.cutoff() / base.cutoff(), 0.5, 0.1);
  const WienerLowPass faint(model, 1e-18, 2e-9);  // σ/√A = 5e−10: W within 1e−6 of 1
  EXPECT_EQ(faint.half_width(), 0);
  EXPECT_EQ(faint.noise_gain(), model.noise_gain());
}

// 50 Hz, 400 samples per turn, a 2 mm disc at 20 µm pitch (as test_plant_inverse.cpp): 40 000 samples, 64² images.
InstrumentSpec wiener_test_scan() {
  InstrumentSpec s;
  s.spiral.sample_rate = 20e3;
  s.spiral.end_radius = 2e-3;
  s.spiral.radial_speed = 1e-3;
  return s;
}

Surface wiener_test_grating() {
  const double half = 2.05e-3;
  const Grid g{512, 512, 2 * half, 2 * half, -half, -half};
  return Surface(grating(g, GratingSpec{400e-6, 50e-9, 0.5, 0.0}), Tilt(0.05 * std::numbers::pi / 180, 0));
}

class WienerTestRecorder final : public ScanObserver {
 public:
  bool sample(const ScanSample& s) override {
    inverse.push_back(s.inverse);
    index.push_back(s.index);
    surface.push_back(s.surface);
    return true;
  }
  std::vector<double> inverse, surface;
  std::vector<std::int64_t> index;
};

TEST(WienerInverseScan, TheStreamedLowPassIsTheConvolutionOfTheExactInverseWithTheTaps) {
  // the same noisy scan with the exact inverse and with the Wiener low-pass: the second's samples, in order, are the
  // first's convolved with the taps (the ends renormalised); the saturated stretch of an uncontrolled scan included
  for (const bool control : {true, false}) {
    InstrumentSpec s = wiener_test_scan();
    s.detector.noise = 1e-10;
    s.controller.enabled = control;
    if (!control) s.detector.range = 1.2e-6;  // the tilt saturates the detector on part of the outer turns
    const Surface surface = wiener_test_grating();
    InstrumentSpec exact = s;
    exact.reconstruction.inverse_filter = InverseFilter::exact;
    WienerTestRecorder with_exact, with_wiener;
    const ScanRun a = simulate_scan(exact, surface, with_exact);
    const ScanRun b = simulate_scan(s, surface, with_wiener);
    for (std::size_t n = 0; n < with_wiener.index.size(); ++n) {
      ASSERT_EQ(with_wiener.index[n], static_cast<long>(n));
    }
    ASSERT_EQ(a.samples, b.samples);
    ASSERT_EQ(with_wiener.index.size(), static_cast<std::size_t>(b.samples));
    for (std::size_t n = 0; n < with_wiener.index.size(); ++n) ASSERT_EQ(with_wiener.index[n], static_cast<long>(n));
    EXPECT_EQ(with_wiener.surface, with_exact.surface);
    const std::optional<WienerLowPass> filter = noise_aware_filter(s, surface);
    ASSERT_TRUE(filter.has_value());
    const std::vector<double> expected = wiener_test_convolve(with_exact.inverse, filter->taps());
    long finite = 0;
    for (std::size_t n = 0; n < expected.size(); ++n) {
      ASSERT_EQ(std::isfinite(expected[n]), std::isfinite(with_wiener.inverse[n])) << n;
      if (!std::isfinite(expected[n])) continue;
      ++finite;
      ASSERT_NEAR(with_wiener.inverse[n], expected[n], 1e-12 * 1e-7) << n;
    }
    EXPECT_GT(finite, b.samples / 2);
  }
}

TEST(WienerInverseScan, WithoutDetectorNoiseTheImagesAreTheExactInversesToTheBit) {
  InstrumentSpec s = wiener_test_scan();
  ASSERT_EQ(s.reconstruction.inverse_filter, InverseFilter::wiener);  // the default
  const Surface surface = wiener_test_grating();
  EXPECT_FALSE(noise_aware_filter(s, surface).has_value());
  InstrumentSpec exact = s;
  exact.reconstruction.inverse_filter = InverseFilter::exact;
  const VirtualScan w = run_virtual_scan(s, surface, image_grid(s, 32));
  const VirtualScan e = run_virtual_scan(exact, surface, image_grid(s, 32));
  ASSERT_EQ(w.topography.size(), e.topography.size());
  EXPECT_EQ(std::memcmp(w.topography.data().data(), e.topography.data().data(), w.topography.size() * sizeof(double)),
            0);  // NaN where invalid in both: compared bit by bit
  EXPECT_EQ(w.inverse_rms_error, e.inverse_rms_error);
  EXPECT_FALSE(w.budget.wiener);
  EXPECT_EQ(w.budget.filter_taps, 1);
}

TEST(WienerInverseScan, ANoisyScanIsImagedFarBetterThanByTheExactInverseOrTheLaggedOneAndAsBudgeted) {
  // σ_d = 1 nm on the grating (at 20 kHz the exact inverse's image noise gain is 13): the budget's noise term against the difference of two scans that differ only in
  // the noise seed (the bias cancels: RMS / √2), the predicted total against the measured error
  InstrumentSpec s = wiener_test_scan();
  s.detector.noise = 1e-9;
  const Surface surface = wiener_test_grating();
  const Grid grid = image_grid(s, 64);
  const VirtualScan w = run_virtual_scan(s, surface, grid);
  InstrumentSpec other_seed = s;
  other_seed.detector.seed = 2;
  const VirtualScan w2 = run_virtual_scan(other_seed, surface, grid);
  InstrumentSpec exact = s;
  exact.reconstruction.inverse_filter = InverseFilter::exact;
  const VirtualScan e = run_virtual_scan(exact, surface, grid);
  ASSERT_TRUE(w.budget.wiener);
  EXPECT_GT(w.budget.filter_taps, 3);
  // what the reconstruction adds (against the imaged true heights): a fifth of the exact inverse's noise or less;
  // the image (with the coarse sampling's floor, 5 nm here) under half of either other image's error
  EXPECT_LT(w.budget.reconstruction, 0.3 * e.budget.reconstruction);
  EXPECT_LT(w.inverse_rms_error, 0.5 * w.lagged_rms_error);
  EXPECT_LT(w.inverse_rms_error, 0.5 * e.inverse_rms_error);
  EXPECT_EQ(w.lagged_rms_error, e.lagged_rms_error);  // the lagged reconstruction is not filtered
  const double noise_measured = levelled_rms_difference(w.topography, w2.topography) / std::sqrt(2.0);
  EXPECT_NEAR(noise_measured / w.budget.noise, 1.0, 0.15);
  // the rest of the reconstruction term is the height the low-pass removes: against the budget's resolution term,
  // measured on the sample along the spiral before any imaging
  const double bias_measured = std::sqrt(std::max(0.0, w.budget.reconstruction * w.budget.reconstruction -
                                                           noise_measured * noise_measured));
  EXPECT_NEAR(bias_measured / w.budget.resolution, 1.0, 0.3);
  EXPECT_NEAR(w.inverse_rms_error / w.budget.predicted, 1.0, 0.15);
  EXPECT_GT(w.budget.resolution, 0.0);
  EXPECT_GT(w.budget.resolution_prior, 0.0);
  EXPECT_GT(w.budget.prior_increment, 0.0);
  EXPECT_LT(w.budget.image_noise_gain, 0.2 * w.budget.exact_image_noise_gain);
}

TEST(WienerInverseScan, AFlatSamplesTiltAndTheRotationsHarmonicsPassTheLowPass) {
  // a flat topography has no height change of its own (A = 0): the prior's floor keeps W ≥ 0.99 up to the rotation's
  // harmonic N + 1, so the tilt passes and the image of the (levelled) flat sample is noise only — below the lagged
  // image's error, where a prior of 0 filtered the tilt's first harmonic away (nanometres)
  InstrumentSpec s = wiener_test_scan();
  s.detector.noise = 1e-10;
  const double half = 2.05e-3;
  const Surface surface(HeightMap(Grid{64, 64, 2 * half, 2 * half, -half, -half}, std::vector<double>(64 * 64, 0.0)),
                        Tilt(0.05 * std::numbers::pi / 180, 0));
  EXPECT_EQ(prior_increment(s, surface), 0.0);
  const std::optional<WienerLowPass> filter = noise_aware_filter(s, surface);
  ASSERT_TRUE(filter.has_value());
  const double omega = 2 * std::numbers::pi * (s.controller.harmonics + 1) * s.spiral.spindle_frequency /
                       s.spiral.sample_rate;
  double response = filter->taps()[0];
  for (std::size_t k = 1; k < filter->taps().size(); ++k)
    response += 2 * filter->taps()[k] * std::cos(static_cast<double>(k) * omega);
  EXPECT_NEAR(response, 0.99, 0.005);
  const VirtualScan v = run_virtual_scan(s, surface, image_grid(s, 64));
  EXPECT_LT(v.inverse_rms_error, v.lagged_rms_error);
  EXPECT_LT(v.inverse_rms_error, 2 * v.budget.noise);
}

TEST(WienerInverseScan, ADetectorSaturatedByItsNoiseLeavesNaNErrorsNotAnInputError) {
  // σ_d = 1 µm against a ±2 µm range: 4.7 % of the samples saturate, scattered; the inverse images (exact and
  // Wiener) keep a handful of pixels, too few (or too few in common with the lagged image) to level: the errors are
  // NaN (null in the sidecar) instead of an InvalidParameter("map") thrown from the levelling
  InstrumentSpec s;
  s.spiral.sample_rate = 20e3;
  s.spiral.radial_speed = 1e-3;
  s.detector.noise = 1e-6;
  const double half = 4.08e-3;
  const Surface surface(grating(Grid{512, 512, 2 * half, 2 * half, -half, -half}, GratingSpec{800e-6, 50e-9, 0.5, 0.0}),
                        Tilt(0.05 * std::numbers::pi / 180, 0));
  VirtualScanOptions options;
  options.compare_without_control = false;
  const VirtualScan v = run_virtual_scan(s, surface, image_grid(s, 128), options);
  EXPECT_GT(v.saturated_fraction, 0.01);
  EXPECT_LT(v.topography.valid_count(), 1000u);
  for (const double e : {v.topography_rms_error, v.inverse_rms_error, v.lagged_rms_error})
    EXPECT_TRUE(std::isnan(e) || e > 0.0);
  if (v.topography.valid_count() < 3) {
    EXPECT_TRUE(std::isnan(v.topography_rms_error));
  }
}

}  // namespace
