// The FM fit (`spectroscopy fit` of a frequency-shift curve): its forward model against the small-amplitude limit,
// and estimates within 3 standard errors of the truth on synthetic data made by the FM forward model (exact FM
// orbits of `tapping fm`) from a known DMT + vdW law with Gaussian noise of a fixed seed.
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/fit.hpp"

using namespace afmkit;
using namespace afmkit::spectroscopy;

namespace {

// k = 40 N/m, f0 = 300 kHz, Q = 400, A = 5 nm
FmFitSettings settings(double amplitude = 5e-9) { return {40.0, 300e3, 400.0, amplitude}; }

constexpr double kHamaker = 1e-19, kModulus = 1e9, kRadius = 10e-9, kOffset = 0.5e-9;

FitOptions truth() {
  FitOptions o;
  o.law = "dmt";
  o.law_values = {{"effective_modulus", kModulus}, {"tip_radius", kRadius}, {"hamaker", kHamaker}};
  o.initial = {{"distance_offset", kOffset}};
  return o;
}

/// n distances from 10 nm down to 3.5 nm: the turning point from 5.5 nm above the surface into the DMT contact.
std::vector<double> distances(int n) {
  std::vector<double> z;
  for (int i = 0; i < n; ++i) z.push_back(10e-9 - 6.5e-9 * i / (n - 1));
  return z;
}

}  // namespace

TEST(FitFm, ForwardModelHasTheSmallAmplitudeLimit) {
  // A = 0.01 nm far out of contact: Δf = −f0 k_ts/(2k) with k_ts = dF/dd of the vdW sphere–plane force
  // F = −A_H R/(6 d²): Δf = −f0 A_H R/(6 k d³) (+ the offset), d = distance + distance_offset
  FitOptions o = truth();
  o.initial["frequency_shift_offset"] = 3.0;
  const std::vector<double> z = {6.5e-9, 4.5e-9, 2.5e-9};
  const FmPrediction p = predict_fm_curve(z, settings(0.01e-9), o);
  for (std::size_t i = 0; i < z.size(); ++i) {
    const double d = z[i] + kOffset;
    const double expected = -300e3 * kHamaker * kRadius / (6.0 * 40.0 * d * d * d) + 3.0;
    EXPECT_NEAR(p.frequency_shift[i], expected, 1e-3 * std::abs(expected - 3.0)) << "d = " << d;
    EXPECT_NEAR(p.dissipation[i], 0.0, 1e-30);  // DMT + vdW is conservative
    EXPECT_FALSE(p.contact[i]);
  }
}

TEST(FitFm, RetractOfAConservativeLawRetracesTheApproach) {
  // DMT + vdW at A = 5 nm has no fold along this curve and dissipates nothing: the retract (down to the smallest
  // distance, then back up through the points) meets the approach's orbits
  const std::vector<double> z = distances(12);
  FitOptions o = truth();
  const FmPrediction approach = predict_fm_curve(z, settings(), o);
  o.direction = CurveDirection::retract;
  const FmPrediction retract = predict_fm_curve(z, settings(), o);
  for (std::size_t i = 0; i < z.size(); ++i) {
    EXPECT_NEAR(retract.frequency_shift[i], approach.frequency_shift[i], 1e-6 * std::abs(approach.frequency_shift[i]) + 1e-3)
        << "distance " << z[i];
    EXPECT_EQ(retract.contact[i], approach.contact[i]);
  }
}

TEST(FitFm, DmtEstimatesNearTheTruth) {
  const std::vector<double> z = distances(60);
  const FmPrediction p = predict_fm_curve(z, settings(), truth());
  ASSERT_TRUE(p.contact.back()) << "the curve must reach the contact";
  const double sigma = 1.0;  // Hz
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, sigma);
  FmFitCurve data;
  data.distance = z;
  for (double f : p.frequency_shift) data.frequency_shift.push_back(f + g(rng));
  FitOptions o;
  o.law = "dmt";
  o.law_values = {{"tip_radius", kRadius}, {"effective_modulus", 0.7e9}, {"hamaker", 1.3e-19}};
  o.parameters = {"hamaker", "effective_modulus", "distance_offset"};
  o.initial = {{"distance_offset", 0.3e-9}};
  const FitResult r = fit_fm_curve(data, settings(), o);
  ASSERT_EQ(r.status, FitStatus::ok) << r.solver_status;
  ASSERT_EQ(r.mode, FitMode::fm);
  const double t[] = {kHamaker, kModulus, kOffset};
  for (std::size_t j = 0; j < 3; ++j) {
    std::printf("%s = %g ± %g (truth %g)\n", r.parameters[j].name.c_str(), r.estimates[j], r.standard_errors[j], t[j]);
    EXPECT_TRUE(std::isfinite(r.standard_errors[j]) && r.standard_errors[j] > 0) << r.parameters[j].name;
    EXPECT_LT(std::abs(r.estimates[j] - t[j]), 3.0 * r.standard_errors[j]) << r.parameters[j].name;
  }
  // the residuals are the noise put in; the noise estimated from the scatter about a smooth curve is at least that
  // (the curve's own bend near the contact adds to the second differences: docs/fitting.md#fm-afm), and the reduced
  // χ² is the ratio of the two
  EXPECT_NEAR(r.rms_frequency_shift, sigma, 0.25 * sigma);
  EXPECT_TRUE(r.noise_estimated_frequency_shift);
  EXPECT_GT(r.frequency_shift_noise, 0.7 * sigma);
  const double ratio = r.rms_frequency_shift / r.frequency_shift_noise;
  EXPECT_NEAR(r.reduced_chi2, ratio * ratio, 0.1 * ratio * ratio);
  ASSERT_EQ(r.fitted_frequency_shift.size(), z.size());
  EXPECT_TRUE(r.dissipation.empty());
  EXPECT_TRUE(r.amplitude.empty());
  for (std::size_t j = 0; j < 3; ++j) EXPECT_DOUBLE_EQ(r.correlation[j][j], 1.0);
  EXPECT_GT(r.orbit_evaluations, static_cast<long>(z.size()));
  std::printf("FM fit: %zu points, %d iterations, %ld curves, %ld orbits, %.3f s\n", z.size(), r.iterations,
              r.curve_evaluations, r.orbit_evaluations, r.seconds);
}

TEST(FitFm, DissipationChannelAndFrequencyShiftOffset) {
  // a law that dissipates (departure Hamaker constant larger: the seed's velocity-sign switching) and a measured
  // Δf baseline offset: hamaker and departure_hamaker from Δf and dissipation together, with the offset
  FitOptions t = truth();
  t.law_values["departure_hamaker"] = 1.5e-19;
  t.initial["frequency_shift_offset"] = 4.0;
  const std::vector<double> z = distances(30);
  const FmPrediction p = predict_fm_curve(z, settings(), t);
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  FmFitCurve data;
  data.distance = z;
  for (std::size_t i = 0; i < z.size(); ++i) {
    data.frequency_shift.push_back(p.frequency_shift[i] + 1.0 * g(rng));
    data.dissipation.push_back(p.dissipation[i] + 2e-21 * g(rng));
  }
  FitOptions o;
  o.law = "dmt";
  o.law_values = {{"tip_radius", kRadius}, {"effective_modulus", kModulus}, {"hamaker", 0.8e-19},
                  {"departure_hamaker", 1.2e-19}};
  o.parameters = {"hamaker", "departure_hamaker", "frequency_shift_offset"};
  o.initial = {{"distance_offset", kOffset}, {"frequency_shift_offset", 2.0}};
  o.frequency_shift_noise = 1.0;
  o.dissipation_noise = 2e-21;
  o.allow_energy_gain = false;
  const FitResult r = fit_fm_curve(data, settings(), o);
  ASSERT_EQ(r.status, FitStatus::ok) << r.solver_status;
  const double truth_values[] = {kHamaker, 1.5e-19, 4.0};
  for (std::size_t j = 0; j < 3; ++j) {
    std::printf("%s = %g ± %g (truth %g)\n", r.parameters[j].name.c_str(), r.estimates[j], r.standard_errors[j],
                truth_values[j]);
    EXPECT_LT(std::abs(r.estimates[j] - truth_values[j]), 3.0 * r.standard_errors[j]) << r.parameters[j].name;
  }
  EXPECT_EQ(r.parameters[2].unit, "Hz");
  ASSERT_EQ(r.fitted_dissipation.size(), z.size());
  EXPECT_NEAR(r.rms_dissipation, 2e-21, 0.5e-21);
  EXPECT_FALSE(r.noise_estimated_dissipation);
  std::printf("FM fit with dissipation: %d iterations, %ld curves, %ld orbits, %.3f s\n", r.iterations,
              r.curve_evaluations, r.orbit_evaluations, r.seconds);
}

TEST(FitFm, RefusesWhatCannotBeFitted) {
  FmFitCurve c;
  c.distance = {3e-9, 2e-9, 1e-9};
  c.frequency_shift = {-1.0, -2.0, -3.0};
  FitOptions o = truth();
  o.parameters = {"phase_offset"};  // an AM calibration
  try {
    fit_fm_curve(c, settings(), o);
    FAIL() << "phase_offset accepted for an FM curve";
  } catch (const InvalidParameter& e) {
    EXPECT_NE(std::string(e.what()).find("distance_offset, frequency_shift_offset"), std::string::npos) << e.what();
  }
  o.parameters = {"hamaker"};
  FitOptions am = o;
  am.initial["amplitude_scale"] = 1.1;  // an AM calibration value
  EXPECT_THROW(fit_fm_curve(c, settings(), am), InvalidParameter);
  FitOptions fm_offset_in_am = o;
  fm_offset_in_am.parameters = {"frequency_shift_offset"};
  EXPECT_THROW(fit_parameter_info(fm_offset_in_am, FitMode::am), InvalidParameter);
  FmFitCurve bad = c;
  bad.frequency_shift[1] = std::nan("");
  EXPECT_THROW(fit_fm_curve(bad, settings(), o), InvalidParameter);
  bad = c;
  bad.dissipation = {0.0, 0.0};
  EXPECT_THROW(fit_fm_curve(bad, settings(), o), InvalidParameter);
  EXPECT_THROW(fit_fm_curve(c, settings(0.0), o), InvalidParameter);
  o.parameters = {"hamaker", "effective_modulus", "distance_offset"};  // 3 parameters, 3 residuals
  EXPECT_THROW(fit_fm_curve(c, settings(), o), InvalidParameter);
}

#include "afmkit/spectroscopy/fit_input.hpp"

TEST(FitFmInput, TheFrequencyShiftColumnMakesAnFmCurve) {
  const FitCurveFile f =
      parse_fit_curve("# FM\ndistance (nm); frequency shift (kHz); dissipation (eV)\n10; -0.002; 0.5\n8; -0.01; 1\n"
                      "6; -0.1; 2\n",
                      "fm.csv");
  ASSERT_EQ(f.mode, FitMode::fm);
  ASSERT_EQ(f.fm.distance.size(), 3u);
  EXPECT_DOUBLE_EQ(f.fm.distance[1], 8e-9);
  EXPECT_DOUBLE_EQ(f.fm.frequency_shift[2], -100.0);
  EXPECT_DOUBLE_EQ(f.fm.dissipation[0], 0.5 * 1.602176634e-19);
  EXPECT_TRUE(f.am.distance.empty());
  const FitCurveFile g = parse_fit_curve("z_pm df_mHz\n1000 -500\n900 -600\n800 -700\n", "b");
  EXPECT_EQ(g.mode, FitMode::fm);
  EXPECT_DOUBLE_EQ(g.fm.frequency_shift[1], -0.6);
  EXPECT_TRUE(g.fm.dissipation.empty());
  EXPECT_EQ(parse_fit_curve("distance (nm), amplitude (nm)\n1, 2\n2, 3\n3, 4\n", "a").mode, FitMode::am);
  const auto message = [](const std::string& text) {
    try {
      parse_fit_curve(text, "f.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("distance (nm), df (Hz)\n1, -2\n2, nan\n3, -4\n").substr(0, 10), "f.csv:3:4:");
  EXPECT_NE(message("distance (nm), amplitude (nm), df (Hz)\n1, 2, 3\n").find("f.csv:1:32: both an amplitude"),
            std::string::npos);
  EXPECT_NE(message("distance (nm), df (Hz), phase (deg)\n1, 2, 3\n").find("f.csv:1:25: a phase column in an FM"),
            std::string::npos);
  EXPECT_NE(message("distance (nm), df (V)\n1, 2\n").find("f.csv:1:16: column 'df (V)': unknown frequency unit"),
            std::string::npos);
  EXPECT_NE(message("distance (nm), df (Hz)\n1, 2\n2, 3\n").find("at least 3"), std::string::npos);
  EXPECT_THROW(parse_am_curve("distance (nm), df (Hz)\n1, 2\n2, 3\n3, 4\n", "x"), InputError);
}
