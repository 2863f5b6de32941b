// The forward model of `spectroscopy fit` against the sweep engine it stands on (tapping::sweep_instrument), and
// the parameter transformations.
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"
#include "fit_settings.hpp"

using namespace afmkit;
using namespace afmkit::spectroscopy;

namespace {

FitSettings model_settings() { return afmkit_test::fit_settings(); }

FitOptions dmt() {
  FitOptions o;
  o.law = "dmt";
  o.law_values = {{"effective_modulus", 1e9}, {"tip_radius", 10e-9}, {"hamaker", 1e-19}};
  return o;
}

}  // namespace

TEST(FitModel, ApproachAndRetractMatchTheInstrumentSweep) {
  // the same cantilever and law through tapping::sweep_instrument (physical units: nm, kHz, GPa)
  const tapping::PhysicalCantilever pc(40.0, 300.0, 100.0, 20.0, 1.0);  // Q = 100: short transients
  impact::LawArguments args;
  args.values = {{"effective_modulus", 1.0}, {"tip_radius", 10.0}, {"hamaker", 1e-19}};
  const tapping::TappingModel base(pc.cantilever(), pc.drive(),
                                   pc.normalised_law(impact::LawRegistry::builtin().build("dmt", args)), 0.0);
  std::vector<double> l_nm;
  for (int i = 0; i < 41; ++i) l_nm.push_back(12.0 + 0.25 * i);  // from free to tapping in contact
  tapping::SweepOptions so;
  so.harmonic_balance = false;
  so.parallel = false;
  const tapping::SweepResult sweep = tapping::sweep_instrument(base, l_nm, so);

  FitOptions o = dmt();
  o.initial["distance_offset"] = 0.5e-9;  // model separation = distance + 0.5 nm
  o.integrator_tolerance = 1e-10;         // the sweep's defaults
  o.shooting_tolerance = 1e-11;
  std::vector<double> z;
  for (double l : l_nm) z.push_back(l * 1e-9 - 0.5e-9);
  FitSettings q100 = model_settings();
  q100.quality_factor = 100.0;
  const AmPrediction pred = predict_am_curve(z, q100, o);
  int touching = 0;
  for (std::size_t i = 0; i < z.size(); ++i) {
    const std::size_t k = z.size() - 1 - i;  // the sweep's approach runs from the largest separation
    ASSERT_NEAR(sweep.approach[k].separation, l_nm[i], 1e-12);
    EXPECT_NEAR(pred.amplitude[i], sweep.approach[k].metrics.amplitude * 1e-9, 1e-16) << "l = " << l_nm[i];  // 1e-7 nm: Newton tolerance
    EXPECT_NEAR(pred.phase[i], sweep.approach[k].metrics.phase, 1e-7) << "l = " << l_nm[i];
    touching += pred.contact[i] ? 1 : 0;
  }
  EXPECT_GT(touching, 5);  // the curve reaches the contact
  EXPECT_LT(touching, 41);
  for (bool j : pred.jumped) EXPECT_FALSE(j);  // Q = 100: no jump on this approach (neither in the sweep)
  EXPECT_TRUE(sweep.approach_jumps.empty());
  // the retract branch: after the approach down to the smallest distance
  o.direction = CurveDirection::retract;
  const AmPrediction back = predict_am_curve(z, q100, o);
  for (std::size_t i = 0; i < z.size(); ++i) {
    ASSERT_NEAR(sweep.retract[i].separation, l_nm[i], 1e-12);
    EXPECT_NEAR(back.amplitude[i], sweep.retract[i].metrics.amplitude * 1e-9, 1e-16) << "l = " << l_nm[i];
    EXPECT_NEAR(back.phase[i], sweep.retract[i].metrics.phase, 1e-7) << "l = " << l_nm[i];
  }
}

TEST(FitModel, CalibrationEntersAsDocumented) {
  std::vector<double> z = {12e-9, 8e-9, 6e-9, 5e-9};
  FitOptions o = dmt();
  const AmPrediction a = predict_am_curve(z, model_settings(), o);
  o.initial["phase_offset"] = 0.25;
  const AmPrediction b = predict_am_curve(z, model_settings(), o);
  for (std::size_t i = 0; i < z.size(); ++i) {
    EXPECT_DOUBLE_EQ(a.amplitude[i], b.amplitude[i]);
    EXPECT_NEAR(std::remainder(b.phase[i] - a.phase[i] - 0.25, 2 * M_PI), 0.0, 1e-12);
  }
  // amplitude_scale s: the model runs at A0·s and predicts A_model/s; far from the sample A/A0 is unchanged
  o = dmt();
  o.initial["amplitude_scale"] = 1.2;
  const AmPrediction c = predict_am_curve({40e-9, 39e-9, 38e-9}, model_settings(), o);
  EXPECT_NEAR(c.amplitude[0], 20e-9, 4e-12);
}

// The model oscillates with free_amplitude × amplitude_scale: a start outside the cantilever's amplitude range
// (<= 1 mm) is the user's amplitude_scale, refused by name before any orbit runs (it was the forward model's numerical
// failure at the initial values); at the bound it runs.
TEST(FitModel, ATrueFreeAmplitudeOutOfRangeIsTheUsersAmplitudeScale) {
  FitSettings s = model_settings();
  s.free_amplitude = 0.9e-3;  // in range alone
  FitOptions o = dmt();
  o.initial["amplitude_scale"] = 1.5;  // 1.35 mm
  try {
    (void)predict_am_curve({40e-9, 39e-9, 38e-9}, s, o);
    ADD_FAILURE() << "an out-of-range true amplitude was accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "amplitude_scale");
    EXPECT_NE(std::string(e.what()).find("<= 0.001 m"), std::string::npos) << e.what();
  }
  FitCurve c;
  c.distance = {40e-9, 39e-9, 38e-9, 37e-9};
  c.amplitude = {0.9e-3, 0.9e-3, 0.9e-3, 0.9e-3};
  o.parameters = {"amplitude_scale"};
  EXPECT_THROW((void)fit_am_curve(c, s, o), InvalidParameter);
}

// A warm evaluation stops after the first failing point; how many points it ran (the fit's orbit_evaluations) must not
// depend on the threads' timing, or a record would not replay. Points after the failure are slowed unevenly so that
// a thread-timed stop would run a varying number of them.
TEST(FitModel, AWarmEvaluationRunsTheSamePointsWhateverTheThreadsTiming) {
  const std::size_t n = 100, failing = 40;
  for (int round = 0; round < 5; ++round) {
    std::vector<std::atomic<int>> ran(n);
    const EachPointResult r = each_point(n, true, [&](std::size_t i) {
      ran[i]++;
      if ((i + round) % 3 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
      return i != failing;
    });
    EXPECT_FALSE(r.all);
    const std::size_t block_end = (failing / kEachPointBlock + 1) * kEachPointBlock;
    EXPECT_EQ(r.visited, static_cast<long>(block_end));
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(ran[i].load(), i < block_end ? 1 : 0) << "point " << i;
  }
  const EachPointResult every = each_point(n, true, [](std::size_t) { return true; });
  EXPECT_TRUE(every.all);
  EXPECT_EQ(every.visited, static_cast<long>(n));
}

TEST(FitModel, TransformsKeepTheRange) {
  FitOptions o = dmt();
  o.parameters = {"hamaker", "distance_offset", "amplitude_scale", "phase_offset", "effective_modulus"};
  o.initial["distance_offset"] = 1e-9;
  const auto info = fit_parameter_info(o);
  ASSERT_EQ(info.size(), 5u);
  EXPECT_EQ(info[0].transform, Transform::log);
  EXPECT_EQ(info[0].unit, "J");
  EXPECT_DOUBLE_EQ(info[0].initial, 1e-19);
  EXPECT_EQ(info[1].transform, Transform::identity);
  EXPECT_DOUBLE_EQ(info[1].initial, 1e-9);
  EXPECT_EQ(info[2].transform, Transform::log);
  EXPECT_EQ(info[4].unit, "Pa");
  for (const auto& p : info) {
    EXPECT_DOUBLE_EQ(to_parameter(p, 0.0), p.initial);
    for (double u : {-50.0, -3.0, 0.7, 20.0}) {
      const double x = to_parameter(p, u);
      EXPECT_TRUE(p.transform == Transform::identity || x > p.lower) << p.name;
      const double h = 1e-6;
      EXPECT_NEAR(parameter_derivative(p, u), (to_parameter(p, u + h) - to_parameter(p, u - h)) / (2 * h),
                  1e-6 * std::abs(parameter_derivative(p, u)) + 1e-300)
          << p.name;
    }
  }
  FitParameterInfo both{"x", "m", 2.0, 1.0, 5.0, Transform::logistic, 1.0};
  for (double u : {-40.0, -1.0, 0.0, 3.0, 40.0}) {
    EXPECT_GE(to_parameter(both, u), 1.0);
    EXPECT_LE(to_parameter(both, u), 5.0);
  }
  EXPECT_DOUBLE_EQ(to_parameter(both, 0.0), 2.0);
}

TEST(FitModel, RefusesWhatCannotBeFitted) {
  FitOptions o = dmt();
  o.parameters = {"viscosity"};
  try {
    fit_parameter_info(o);
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "parameters");
    EXPECT_NE(std::string(e.what()).find("kelvin_voigt"), std::string::npos) << e.what();
  }
  o.parameters = {"hamaker", "hamaker"};
  EXPECT_THROW(fit_parameter_info(o), InvalidParameter);
  o.parameters = {"hamaker"};
  o.law_values["hamaker"] = 0.0;  // on a log scale 0 cannot be left
  try {
    fit_parameter_info(o);
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "hamaker");
  }
  o = dmt();
  o.parameters = {};
  EXPECT_THROW(fit_parameter_info(o), InvalidParameter);
}

#include "afmkit/spectroscopy/fit_input.hpp"

TEST(FitInput, ReadsUnitsFromTheHeader) {
  const FitCurve c = parse_am_curve("# measured\ndistance (nm), amplitude (nm), phase (deg)\n10, 9.5, 90\n8, 7.9, "
                                   "120\r\n\n6, 6.1, 135\n",
                                   "curve.csv");
  ASSERT_EQ(c.distance.size(), 3u);
  EXPECT_DOUBLE_EQ(c.distance[1], 8e-9);
  EXPECT_DOUBLE_EQ(c.amplitude[2], 6.1e-9);
  EXPECT_DOUBLE_EQ(c.phase[0], M_PI / 2);
  const FitCurve d = parse_am_curve("z_m\tamp_m\tphi_rad\n1e-8\t9e-9\t1.5\n2e-8\t1e-8\t1.6\n3e-8\t1e-8\t1.57\n", "t");
  EXPECT_DOUBLE_EQ(d.distance[2], 3e-8);
  EXPECT_DOUBLE_EQ(d.phase[1], 1.6);
  const FitCurve e = parse_am_curve("distance (A)  amplitude (nm)\n100 9\n90 8\n80 7\n", "blank");
  EXPECT_DOUBLE_EQ(e.distance[1], 9e-9);
  EXPECT_TRUE(e.phase.empty());
}

TEST(FitInput, NamesLineAndColumnOfBadCells) {
  const auto message = [](const std::string& text) {
    try {
      parse_am_curve(text, "f.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("distance (nm), amplitude (nm)\n1, 2\n2, x\n3, 4\n"),
            "f.csv:3:4: 'x' is not a number (column amplitude (nm))");
  EXPECT_EQ(message("distance (nm), amplitude (nm)\n1, 2\n2, nan\n3, 4\n").substr(0, 9), "f.csv:3:4");
  EXPECT_NE(message("distance, amplitude (nm)\n1, 2\n").find("f.csv:1:1: column 'distance' has no unit"),
            std::string::npos);
  EXPECT_NE(message("distance (nm), amplitude (V)\n1, 2\n").find("f.csv:1:16: column 'amplitude (V)': unknown length"),
            std::string::npos);
  EXPECT_NE(message("distance (nm), amplitude (nm)\n1, 2\n1, 3\n2, 2\n").find("f.csv:3:1: distance 1 (column distance (nm)) repeats line 2"),
            std::string::npos);
  EXPECT_NE(message("distance (nm), amplitude (nm)\n1, 2\n2, 3, 4\n").find("f.csv:3:7: 3 cells"), std::string::npos);
  EXPECT_NE(message("distance (nm), amplitude (nm)\n1, 2\n2, 0\n3, 2\n").find("f.csv:3:4: amplitude 0 is out of range"),
            std::string::npos);
  EXPECT_NE(message("distance (nm), amplitude (nm)\n1, 2\n2, 3\n").find("at least 3"), std::string::npos);
  EXPECT_NE(message("distance (nm), phase (deg)\n1, 2\n").find("no amplitude column"), std::string::npos);
}
