// control::disturbance_from_samples (sampled_disturbance.hpp): the disturbance f of seed-2 eq. 14 from a user's
// samples. Checked against signals built from known harmonics (amplitudes and phases recovered, the Disturbance
// reproducing the samples), against the period average and the residuals computed here, and for the refusals.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <numbers>
#include <vector>

#include "afmkit/control/sampled_disturbance.hpp"
#include "afmkit/core/error.hpp"

using afmkit::InvalidParameter;
using afmkit::control::disturbance_from_samples;

namespace {
constexpr double kSampledPi = std::numbers::pi;

// f(θ) = c0 + Σ F_k sin(kθ + φ_k) at θ_j = 2πj/S, for `periods` periods.
std::vector<double> sampled_harmonics(int s, int periods, double c0, const std::vector<std::array<double, 3>>& h) {
  std::vector<double> out;
  for (int p = 0; p < periods; ++p)
    for (int j = 0; j < s; ++j) {
      const double theta = 2 * kSampledPi * j / s;
      double f = c0;
      for (const auto& [k, amplitude, phase] : h) f += amplitude * std::sin(k * theta + phase);
      out.push_back(f);
    }
  return out;
}
}  // namespace

TEST(SampledDisturbance, RecoversTheHarmonicsOfABandLimitedSignal) {
  const std::vector<std::array<double, 3>> h = {{1, 1.0, 0.0}, {2, 0.25, -2.0}, {5, 0.125, 2.5}};
  const auto d = disturbance_from_samples(sampled_harmonics(33, 1, 0.2, h), 33);
  EXPECT_EQ(d.samples_per_period, 33);
  EXPECT_EQ(d.periods, 1);
  EXPECT_EQ(d.harmonics, 16);  // every k < S/2
  EXPECT_NEAR(d.disturbance.offset, 0.2, 1e-14);
  ASSERT_EQ(d.disturbance.harmonics.size(), 3u);  // the other harmonics are rounding, left out
  for (std::size_t i = 0; i < h.size(); ++i) {
    EXPECT_EQ(d.disturbance.harmonics[i].order, static_cast<int>(h[i][0]));
    EXPECT_NEAR(d.disturbance.harmonics[i].amplitude, h[i][1], 1e-14);
    EXPECT_NEAR(std::remainder(d.disturbance.harmonics[i].phase - h[i][2], 2 * kSampledPi), 0.0, 1e-13);
  }
  EXPECT_LT(d.unrepresented_rms, 1e-14);
  EXPECT_LT(d.non_periodic_rms, 1e-15);
}

TEST(SampledDisturbance, ReproducesArbitrarySamplesAtOddCounts) {
  // any S samples (S odd: no Nyquist term) are exactly a trigonometric polynomial of degree (S - 1)/2
  std::vector<double> f = {0.3, -1.2, 2.5, 0.0, 0.7, -0.4, 1.9};
  const auto d = disturbance_from_samples(f, 7);
  for (int j = 0; j < 7; ++j) EXPECT_NEAR(d.disturbance(2 * kSampledPi * j / 7), f[j], 1e-14);
}

TEST(SampledDisturbance, AveragesThePeriodsAndReportsWhatTheModelCannotHold) {
  // two periods of S = 8 that differ by ±e: the average is the mean; what is left is |e| at every sample
  const int s = 8;
  std::vector<double> f;
  const double e = 0.01;
  for (int p = 0; p < 2; ++p)
    for (int j = 0; j < s; ++j) f.push_back(std::sin(2 * kSampledPi * j / s) + (p == 0 ? e : -e));
  const auto d = disturbance_from_samples(f, s, 2);
  EXPECT_EQ(d.periods, 2);
  EXPECT_EQ(d.harmonics, 2);
  EXPECT_NEAR(d.non_periodic_rms, e, 1e-15);
  EXPECT_NEAR(d.disturbance.offset, 0.0, 1e-15);
  // the Nyquist term (-1)^j is what no harmonic k < S/2 holds
  std::vector<double> nyquist(s);
  for (int j = 0; j < s; ++j) nyquist[j] = (j % 2 ? -0.5 : 0.5);
  EXPECT_NEAR(disturbance_from_samples(nyquist, s).unrepresented_rms, 0.5, 1e-14);
}

TEST(SampledDisturbance, RefusesSamplesThatAreNotWholeFinitePeriods) {
  EXPECT_THROW(disturbance_from_samples({0.0, 1.0, 2.0}, 2), InvalidParameter);
  EXPECT_THROW(disturbance_from_samples({}, 2), InvalidParameter);
  EXPECT_THROW(disturbance_from_samples({0.0, NAN}, 2), InvalidParameter);
  EXPECT_THROW(disturbance_from_samples({0.0}, 1), InvalidParameter);
  try {
    disturbance_from_samples({0.0, 1.0, 2.0}, 2);
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "signal");
    EXPECT_NE(std::string(e.what()).find("must cover whole rotation periods"), std::string::npos);
  }
}
