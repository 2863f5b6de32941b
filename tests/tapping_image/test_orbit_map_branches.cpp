// The orbit map's branches, hysteresis and engagement, and the quasi-static loop on them, on a sweep written by hand
// whose two branches are straight lines (so every expectation is a closed form): an attractive branch L, amplitude
// A_L(l) = 10 + 0.5 (l − 8) for l in [7.5, 20] (phase 2 rad: H_c = −Γ cos φ > 0 at ω = ω_n), a repulsive branch H,
// A_H(l) = 5 + l for l in [0, 12.5] (phase 1 rad); the approach leaves L at 7.5 (its last stable orbit at 7.6), the
// retract leaves H at 12.5 (last at 12.4). A0 = Γ Q = 20 (Q = 100, Γ = 0.2, ω = ω_n = 1); lengths in nm.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/impact/force_law.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/tapping/image/quasi_static.hpp"
#include "image_fixtures.hpp"

namespace afmkit::tapping::image {
namespace {

TappingModel synth_model() {
  return {Cantilever(1.0, 100.0), Drive(0.2, 1.0), impact::ForceLaw(impact::PiecewiseLinearLaw(10.0, 10.0)), 20.0};
}
double synth_a_l(double l) { return 10.0 + 0.5 * (l - 8.0); }
double synth_a_h(double l) { return 5.0 + l; }

SweepPoint synth_point(double l, SweepDirection d, bool on_l, bool jumped) {
  SweepPoint p;
  p.separation = p.parameter = l;
  p.direction = d;
  p.metrics.amplitude = on_l ? synth_a_l(l) : synth_a_h(l);
  p.metrics.phase = on_l ? 2.0 : 1.0;
  p.metrics.peak_force = on_l ? -0.01 : 0.1 * (12.5 - l);
  p.metrics.contact_dissipation = on_l ? 0.0 : 0.01;
  p.metrics.duration = 2.0 * std::numbers::pi;
  p.jumped = jumped;
  return p;
}

SweepJump synth_jump(SweepDirection d, double at, double from, bool from_l) {
  SweepJump j;
  j.direction = d;
  j.separation = j.parameter = at;
  j.from.separation = from;
  j.from_metrics = synth_point(from, d, from_l, false).metrics;
  return j;
}

SweepResult synth_sweep() {
  SweepResult r;
  for (int k = 20; k >= 0; --k)
    r.approach.push_back(synth_point(k, SweepDirection::approach, k >= 8, k == 7));
  for (int k = 0; k <= 20; ++k)
    r.retract.push_back(synth_point(k, SweepDirection::retract, k >= 13, k == 13));
  r.jumps = {synth_jump(SweepDirection::approach, 7.5, 7.6, true), synth_jump(SweepDirection::retract, 12.5, 12.4, false)};
  return r;
}

const OrbitMap& synth_map() {
  static const OrbitMap m = OrbitMap::from_sweep(synth_model(), synth_sweep());
  return m;
}

TEST(OrbitMapBranches, TwoBranchesWithTheirEndsAtTheLocatedJumps) {
  const OrbitMap& m = synth_map();
  ASSERT_EQ(m.branches().size(), 2u);
  const int l = m.approach_branch(15.0), h = m.retract_branch(5.0);
  EXPECT_NE(l, h);
  EXPECT_EQ(m.retract_branch(15.0), l);  // the retract lands on L, the approach on H: one branch each
  EXPECT_EQ(m.approach_branch(5.0), h);
  EXPECT_DOUBLE_EQ(m.branches()[static_cast<std::size_t>(l)].lower, 7.5);
  EXPECT_DOUBLE_EQ(m.branches()[static_cast<std::size_t>(l)].upper, 20.0);
  EXPECT_DOUBLE_EQ(m.branches()[static_cast<std::size_t>(h)].lower, 0.0);
  EXPECT_DOUBLE_EQ(m.branches()[static_cast<std::size_t>(h)].upper, 12.5);
  EXPECT_NEAR(m.free_amplitude(), 20.0, 1e-12);
  // linear interpolation is exact on straight branches, the last stable orbit before a jump included
  for (double x : {7.6, 8.3, 11.25, 19.9}) EXPECT_NEAR(m.at(l, x).amplitude, synth_a_l(x), 1e-12) << x;
  for (double x : {0.2, 6.5, 12.4}) EXPECT_NEAR(m.at(h, x).amplitude, synth_a_h(x), 1e-12) << x;
  EXPECT_EQ(regime_of(m.at(l, 10.0).in_phase_force, m.drive_amplitude()), Regime::attractive);
  EXPECT_EQ(regime_of(m.at(h, 10.0).in_phase_force, m.drive_amplitude()), Regime::repulsive);
  EXPECT_NEAR(m.at(h, 10.0).phase(), 1.0, 1e-12);
}

TEST(OrbitMapBranches, TheInstrumentKeepsItsBranchWhileItExists) {
  const OrbitMap& m = synth_map();
  const int l = m.approach_branch(15.0), h = m.retract_branch(5.0);
  EXPECT_EQ(m.follow(l, 10.0), l);  // both exist at 10: stay
  EXPECT_EQ(m.follow(h, 10.0), h);
  EXPECT_EQ(m.follow(l, 7.4), h);   // below L's end: the approach's branch
  EXPECT_EQ(m.follow(h, 12.6), l);  // above H's end: the retract's branch
}

TEST(OrbitMapBranches, EngagingFollowsTheApproachAcrossItsJump) {
  const OrbitMap& m = synth_map();
  const int l = m.approach_branch(15.0), h = m.retract_branch(5.0);
  const OrbitMap::Engaged high = m.engage(12.0);  // on L: 10 + 0.5 (l − 8) = 12
  EXPECT_EQ(high.branch, l);
  EXPECT_NEAR(high.separation, 12.0, 1e-12);
  const OrbitMap::Engaged end = m.engage(9.85);  // on L between its last grid point (8) and its last orbit (7.6)
  EXPECT_EQ(end.branch, l);
  EXPECT_NEAR(end.separation, 7.7, 1e-12);
  const OrbitMap::Engaged low = m.engage(9.0);  // L ends at 9.8: lands on H at 12.5 > 9, goes on down to 4
  EXPECT_EQ(low.branch, h);
  EXPECT_NEAR(low.separation, 4.0, 1e-12);
  EXPECT_EQ(m.engage(4.0).branch, -1);  // never that low above l = 0
}

// SI: 1 model length = 1 nm, time unit 1/ω0 with f0 = 300 kHz
UnitScales synth_scales() {
  UnitScales s;
  s.time = 1.0 / (2.0 * std::numbers::pi * 300e3);
  return s;
}

ImagingResult synth_image(double step_height, double speed) {
  const scan::Grid g{600, 600, 1.2e-6, 1.2e-6, -0.6e-6, -0.6e-6};
  const scan::Surface s(scan::steps(g, {0.6e-6, step_height, 0.0}), scan::Tilt(0.0, 0.0));
  RasterSpec r;
  r.pixels = 64;
  r.lines = 2;
  r.width = r.height = 1e-6;
  r.tip_speed = speed;
  FeedbackSpec f;
  f.setpoint = 0.6;  // 12 nm: on L at 12 nm, on H at 7 nm
  QuasiStaticEngine e(synth_map(), synth_scales(), 2.0 * 100.0 / (2.0 * std::numbers::pi * 300e3), f.lockin_bandwidth);
  return scan_image(e, s, r, f);
}

TEST(OrbitMapBranches, AStepWithinTheMarginIsImagedWithItsHeight) {
  const ImagingResult r = synth_image(3e-9, 2e-6);  // margin 12 − 7.5 = 4.5 nm
  EXPECT_NEAR(r.engaged_separation, 12e-9, 1e-18);
  EXPECT_NEAR(test::right_minus_left_quarter(r.trace.height), 3e-9, 1e-13);
  for (double v : r.trace.regime.data()) EXPECT_EQ(v, 1.0);
  EXPECT_EQ(r.trace.regime_switches[0], 0);
}

TEST(OrbitMapBranches, AStepBeyondTheMarginSwitchesToRepulsiveAndIsImagedLowerByTheBranchesSeparation) {
  const ImagingResult r = synth_image(6e-9, 20e-6);
  // trace: on the upper terrace the loop holds H at 7 nm instead of L at 12 nm: 6 − 5 = 1 nm
  EXPECT_NEAR(test::right_minus_left_quarter(r.trace.height), 1e-9, 1e-13);
  EXPECT_EQ(r.trace.regime(0, 0), 1.0);
  EXPECT_EQ(r.trace.regime(63, 0), 2.0);
  EXPECT_EQ(r.trace.regime_switches[0], 1);
  // retrace: it starts on H on the upper terrace; stepping down the separation rises by 6 nm to 13 nm, beyond H's
  // end (12.5): back to L at 12 nm on the lower terrace, so the retrace shows the same 1 nm
  EXPECT_EQ(r.retrace.regime(63, 0), 2.0);
  EXPECT_EQ(r.retrace.regime(0, 0), 1.0);
  EXPECT_NEAR(test::right_minus_left_quarter(r.retrace.height), 1e-9, 1e-13);
  const ImagingMetrics m = imaging_metrics(r);
  EXPECT_GT(m.fraction_repulsive, 0.0);
  EXPECT_GT(m.fraction_attractive, 0.0);
  EXPECT_NEAR(m.fraction_attractive + m.fraction_repulsive, 1.0, 1e-15);
}

}  // namespace
}  // namespace afmkit::tapping::image
