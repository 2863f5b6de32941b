// AM-AFM imaging with Z feedback, quasi-static engine (docs/theory-tapping.md#quasi-static-imaging). The
// expectations come from the instrument sweep's own points and jumps (sweep_instrument), interpolated here, not
// from the orbit map's branches, tracks or engagement: a flat sample holds the set-point and images zero height; a
// step is imaged with its height on one branch; at a set-point inside the bistable window a step higher than the
// attractive branch's margin (from the set-point's separation down to the approach's located jump) switches the tip
// to the repulsive branch and is imaged lower by the separation between the branches (test_orbit_map_branches.cpp
// checks the engagement across a jump and the hysteresis rule in closed form).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/force_law.hpp"
#include "afmkit/scan/levelling.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/tapping/image/quasi_static.hpp"
#include "afmkit/tapping/image/time_domain.hpp"
#include "afmkit/tapping/units.hpp"
#include "image_fixtures.hpp"

namespace afmkit::tapping::image {
namespace {

// k = 40 N/m, f0 = 300 kHz, Q = 400, A0 = 10 nm at resonance; DMT: E* = 1 GPa, R = 10 nm, A_H = 6.4e-20 J,
// a0 = 0.165 nm (the law's defaults). Lengths in nm. The approach stays on the attractive branch down to 0.28 nm,
// the retract on the repulsive one up to 8.8 nm: at A_sp = A0/2 both hold the set-point.
constexpr double kQimgF0 = 300e3, kQimgQ = 400.0, kQimgA0 = 10.0, kQimgSetpoint = 0.5;
const PhysicalCantilever& qimg_cantilever() {
  static const PhysicalCantilever pc(40.0, 300.0, kQimgQ, kQimgA0, 1.0);
  return pc;
}
TappingModel qimg_model() { return test::dmt_defaults_model(qimg_cantilever()); }

struct QimgCase {
  SweepResult sweep;
  OrbitMap map;
};
const QimgCase& qimg_case() {
  static const QimgCase c = [] {
    SweepOptions o;
    o.harmonic_balance = false;
    o.transient.max_periods = 1000;  // the non-periodic window below the first approach jump: 1000 periods settle the
                                     // jumps used here as 4000 do, at half the cost
    SweepResult s = sweep_instrument(qimg_model(), 0.0, 12.0, 48, o);
    OrbitMap m = OrbitMap::from_sweep(qimg_model(), s);
    return QimgCase{std::move(s), std::move(m)};
  }();
  return c;
}

/// The separation where the sweep points `pts` (one direction, up to its first jump) reach amplitude `a`, by linear
/// interpolation between two consecutive points; nullopt when they do not.
std::optional<double> qimg_crossing(const std::vector<SweepPoint>& pts, double a) {
  for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
    if (pts[k + 1].jumped) break;
    const double a0 = pts[k].metrics.amplitude - a, a1 = pts[k + 1].metrics.amplitude - a;
    if ((a0 <= 0) != (a1 <= 0))
      return pts[k].separation + (pts[k + 1].separation - pts[k].separation) * a0 / (a0 - a1);
  }
  return std::nullopt;
}
/// The first jump of a direction.
const SweepJump& qimg_first_jump(SweepDirection d) {
  for (const SweepJump& j : qimg_case().sweep.jumps)
    if (j.direction == d) return j;
  throw std::runtime_error("no jump");
}

scan::Surface qimg_surface(scan::HeightMap map) { return scan::Surface(std::move(map), scan::Tilt(0.0, 0.0)); }
scan::Grid qimg_grid(double size, long n) { return {n, n, size, size, -0.5 * size, -0.5 * size}; }

RasterSpec qimg_raster(long pixels, long lines, double size, double speed) {
  RasterSpec r;
  r.pixels = pixels;
  r.lines = lines;
  r.width = r.height = size;
  r.tip_speed = speed;
  return r;
}

ImagingResult qimg_scan(const scan::Surface& s, const RasterSpec& r, const FeedbackSpec& f) {
  QuasiStaticEngine engine(qimg_case().map, qimg_cantilever().scales(), 2.0 * kQimgQ / (2 * std::numbers::pi * kQimgF0),
                           f.lockin_bandwidth);
  return scan_image(engine, s, r, f);
}

void qimg_check_bistable_window() {
  // the case the other tests rely on: the approach leaves the attractive branch below the retract's jump off the
  // repulsive branch, and both branches pass through the set-points used
  const SweepJump& down = qimg_first_jump(SweepDirection::approach);
  const SweepJump& up = qimg_first_jump(SweepDirection::retract);
  EXPECT_LT(down.separation, up.separation);
  const OrbitMap& m = qimg_case().map;
  EXPECT_GE(m.branches().size(), 2u);
  const int att = m.approach_branch(5.0), rep = m.retract_branch(5.0);
  EXPECT_NE(att, rep);
  EXPECT_EQ(regime_of(m.at(att, 5.0).in_phase_force, m.drive_amplitude()), Regime::attractive);
  EXPECT_EQ(regime_of(m.at(rep, 5.0).in_phase_force, m.drive_amplitude()), Regime::repulsive);
  EXPECT_FALSE(m.separations_at_amplitude(att, kQimgSetpoint * kQimgA0).empty());
  EXPECT_FALSE(m.separations_at_amplitude(rep, kQimgSetpoint * kQimgA0).empty());
}

void qimg_check_flat() {
  const scan::Surface s = qimg_surface(scan::flat(qimg_grid(1e-6, 64)));
  FeedbackSpec f;
  f.setpoint = kQimgSetpoint;
  const ImagingResult r = qimg_scan(s, qimg_raster(32, 8, 1e-6, 2e-6), f);
  const double a0 = kQimgA0 * 1e-9;
  const std::optional<double> l = qimg_crossing(qimg_case().sweep.approach, kQimgSetpoint * kQimgA0);
  ASSERT_TRUE(l.has_value());
  EXPECT_NEAR(r.engaged_separation, *l * 1e-9, 1e-3 * 1e-9);
  for (const ImageChannels* c : {&r.trace, &r.retrace}) {
    for (double e : c->error.data()) EXPECT_LT(std::abs(e), 1e-9 * a0);
    for (double z : c->height.data()) EXPECT_NEAR(z, r.engaged_separation, 1e-15);
  }
  const ImagingMetrics m = imaging_metrics(r);
  EXPECT_LT(m.trace_height_rms_error, 1e-15);
  EXPECT_EQ(m.switches_per_line, 0.0);
}

void qimg_check_step_on_one_branch() {
  // one step up at x = 0 (terraces 2 µm wide over a 1 µm scan), lower than the margin of the attractive branch
  const double a_sp = kQimgSetpoint * kQimgA0;
  const double l_att = *qimg_crossing(qimg_case().sweep.approach, a_sp);
  const double margin = l_att - qimg_first_jump(SweepDirection::approach).separation;  // nm
  const double height = 0.5 * margin * 1e-9;
  const scan::Grid g = qimg_grid(1.2e-6, 600);
  scan::HeightMap steps = scan::steps(g, {0.6e-6, height, 0.0});  // z = height · floor(x / 0.6 µm): -h | 0
  const scan::Surface s = qimg_surface(std::move(steps));
  FeedbackSpec f;
  f.setpoint = kQimgSetpoint;
  const ImagingResult r = qimg_scan(s, qimg_raster(64, 4, 1e-6, 2e-6), f);
  EXPECT_NEAR(test::right_minus_left_quarter(r.trace.height), height, 1e-4 * height);
  EXPECT_NEAR(test::right_minus_left_quarter(r.retrace.height), height, 1e-4 * height);
  for (double v : r.trace.regime.data()) EXPECT_EQ(v, 1.0);  // attractive throughout
}

void qimg_check_step_switching_branch() {
  const double a_sp = kQimgSetpoint * kQimgA0;
  const double l_att = *qimg_crossing(qimg_case().sweep.approach, a_sp);
  const std::optional<double> l_rep = qimg_crossing(qimg_case().sweep.retract, a_sp);
  ASSERT_TRUE(l_rep.has_value());
  const double margin = l_att - qimg_first_jump(SweepDirection::approach).separation;
  const double height = 1.5 * margin * 1e-9;
  const scan::Grid g = qimg_grid(1.2e-6, 600);
  const scan::Surface s = qimg_surface(scan::steps(g, {0.6e-6, height, 0.0}));
  FeedbackSpec f;
  f.setpoint = kQimgSetpoint;
  // crossed in 0.1 ms (a 2 nm sample pixel at 20 µm/s): the loop cannot follow, the separation drops by the step
  const ImagingResult r = qimg_scan(s, qimg_raster(64, 4, 1e-6, 20e-6), f);
  // trace: the step up pushes the tip below the attractive branch's end: repulsive on the upper terrace, which is
  // imaged lower by l_att − l_rep
  const double expected = height - (l_att - *l_rep) * 1e-9;
  EXPECT_NEAR(test::right_minus_left_quarter(r.trace.height), expected, 0.01e-9);
  EXPECT_EQ(r.trace.regime(0, 0), 1.0);
  EXPECT_EQ(r.trace.regime(63, 0), 2.0);
  EXPECT_GE(r.trace.regime_switches[0], 1);
}

void qimg_check_time_domain_switch() {
  // the same step, scanned by the time-domain engine (on this sweep's map for the engagement only): the tip meets
  // the edge on the attractive branch; below the approach's jump (where the map says the attractive branch ends) the
  // orbit can only land on the repulsive branch. 24 pixels of 48 drive cycles (the loop, K_i = 2000 1/s, and the
  // cantilever, τ_c = 2Q/ω0 = 127 cycles, settle over the following pixels)
  const double a_sp = kQimgSetpoint * kQimgA0;
  const double l_att = *qimg_crossing(qimg_case().sweep.approach, a_sp);
  const double margin = l_att - qimg_first_jump(SweepDirection::approach).separation;
  const double height = 1.5 * margin * 1e-9;
  const scan::Surface s = qimg_surface(scan::steps(qimg_grid(1.2e-6, 600), {0.6e-6, height, 0.0}));
  FeedbackSpec f;
  f.setpoint = kQimgSetpoint;
  const long pixels = 24;
  const double cycles = 48.0;
  TimeDomainOptions o;
  o.lockin_bandwidth = f.lockin_bandwidth;
  TimeDomainEngine engine(qimg_model(), qimg_case().map, qimg_cantilever().scales(), o);
  const ImagingResult r =
      scan_image(engine, s, qimg_raster(pixels, 1, 1e-6, 1e-6 / static_cast<double>(pixels) * kQimgF0 / cycles), f);
  // the edge is between pixels 11 and 12: attractive before it, repulsive at once in the edge's pixel (the regime
  // follows the force's first harmonic cycle by cycle), and repulsive once the loop has settled on the upper terrace
  // (in between, while the loop lifts Z by several nm per pixel, the orbit is between the branches)
  for (long i = 0; i < pixels / 2; ++i) EXPECT_EQ(r.trace.regime(i, 0), 1.0) << "pixel " << i;
  EXPECT_EQ(r.trace.regime(pixels / 2, 0), 2.0);
  for (long i = 3 * pixels / 4; i < pixels; ++i) EXPECT_EQ(r.trace.regime(i, 0), 2.0) << "pixel " << i;
  // settled on the repulsive branch: the upper terrace imaged lower by l_att − l_rep, as the quasi-static engine
  // images it (qimg_check_step_switching_branch). Bound: the loop's residual at the last pixel, t = 12 pixels after
  // the edge, e^{−(t − τ_c − τ_li)/τ_L} of the change, τ_L = 1/(K_i S) with S = dA/dl of the repulsive branch at l_rep
  const std::optional<double> l_rep = qimg_crossing(qimg_case().sweep.retract, a_sp);
  ASSERT_TRUE(l_rep.has_value());
  const double expected = height - (l_att - *l_rep) * 1e-9;
  const OrbitMap& m = qimg_case().map;
  const int rep = m.retract_branch(*l_rep);
  const double dl = 0.1;
  const double slope = (m.at(rep, *l_rep + dl).amplitude - m.at(rep, *l_rep - dl).amplitude) / (2.0 * dl);
  const double tau_c = 2.0 * kQimgQ / (2.0 * std::numbers::pi * kQimgF0), tau_li = 1.0 / (2.0 * std::numbers::pi * 5e3);
  const double t = static_cast<double>(pixels / 2) * cycles / kQimgF0;
  const double bound = std::abs(expected) * std::exp(-(t - tau_c - tau_li) * f.integral_gain * slope);
  ASSERT_LT(bound, 0.1 * height);
  EXPECT_NEAR(r.trace.height(pixels - 1, 0) - r.trace.height(0, 0), expected, bound);
}

// One test (one process under ctest): the sweep, about 1 s of CPU, is computed once.
TEST(QuasiStaticImaging, ADmtSampleIsImagedAsTheSweepPredicts) {
  {
    SCOPED_TRACE("the case has a bistable window");
    qimg_check_bistable_window();
  }
  {
    SCOPED_TRACE("a flat sample holds the set-point and images zero height");
    qimg_check_flat();
  }
  {
    SCOPED_TRACE("a step on one branch is imaged with its height");
    qimg_check_step_on_one_branch();
  }
  {
    SCOPED_TRACE("a step that pushes the tip off the attractive branch is imaged lower by the branches' separation");
    qimg_check_step_switching_branch();
  }
  {
    SCOPED_TRACE("the time-domain engine switches to the repulsive branch at the edge, as the map says");
    qimg_check_time_domain_switch();
  }
}

TEST(QuasiStaticImaging, BadFeedbackAndRasterNameTheirParameter) {
  const auto name_of = [](auto&& f) {
    try {
      f();
    } catch (const InvalidParameter& e) {
      return e.parameter();
    }
    return std::string("none");
  };
  FeedbackSpec f;
  f.setpoint = 1.0;
  EXPECT_EQ(name_of([&] { f.validate(); }), "setpoint");
  f = {};
  f.integral_gain = -1.0;
  EXPECT_EQ(name_of([&] { f.validate(); }), "integral_gain");
  f = {};
  f.proportional_gain = -1.0;
  EXPECT_EQ(name_of([&] { f.validate(); }), "proportional_gain");
  f = {};
  f.z_max = f.z_min;
  EXPECT_EQ(name_of([&] { f.validate(); }), "z_max");
  // a sample smaller than the scan
  const scan::Surface s = qimg_surface(scan::flat(qimg_grid(0.5e-6, 16)));
  EXPECT_EQ(name_of([&] { qimg_scan(s, qimg_raster(16, 4, 1e-6, 2e-6), FeedbackSpec{}); }), "scan_size");
}

}  // namespace
}  // namespace afmkit::tapping::image
