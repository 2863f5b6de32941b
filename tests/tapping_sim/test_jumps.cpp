// Jumps of the instrument sweep are discontinuities of the continued orbit (a change of branch), not large steps.
// Where the orbit changes continuously — through grazing for laws (10), (11) and (26) of seed 1, and on a coarse
// grid along a steep but smooth curve — no jump may be reported; real jumps (fold of the demo retract, the approach
// jump at grazing of the demo case) still are. Continuity is established independently of the sweep by a slow
// separation ramp simulated with the adaptive integrator (plain time simulation, no shooting): the stroboscopic
// state moves by at most a bounded multiple of the separation step, and it lands on the sweep's orbits.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "fixtures.hpp"

namespace afmkit::tapping {
namespace {

using testing::make_model;

SimulationOptions adaptive() {
  SimulationOptions o;
  o.integrator = Integrator::adaptive;
  o.relative_tolerance = 1e-10;
  return o;
}

TipState run(const TappingModel& m, TipState y, int periods, const SimulationOptions& o = adaptive()) {
  for (int k = 0; k < periods; ++k) y = simulate(m, 0.0, y, m.period(), o).state;
  return y;
}

double distance(TipState a, TipState b, double omega) {
  return std::hypot(a.position - b.position, (a.velocity - b.velocity) / omega);
}

struct RampResult {
  double max_rate = 0.0;     // max |Δy| / |Δl| between consecutive settled states (scaled state (x, ẋ/ω))
  double max_rate_at = 0.0;  // separation where it occurs
  /// Rate on the halves of that interval over max_rate: ≈ 1 where the settled state is continuous in l (the
  /// rate is a slope), ≈ 2 at a jump (the same finite change over half the interval).
  double refinement_ratio = 0.0;
  std::vector<TipState> at_points;  // settled state at each sweep separation passed
};

/// Quasi-static ramp from points.front() to points.back() through every sweep separation in `points`, in
/// sub-steps of at most `step`, settling `settle` periods at each sub-step (plain time simulation).
RampResult ramp(const TappingModel& base, TipState y, const std::vector<double>& points, double step, int settle,
                const SimulationOptions& o = adaptive()) {
  const double omega = base.drive.frequency;
  RampResult r;
  y = run(base.with_separation(points.front()), y, settle, o);
  r.at_points.push_back(y);
  TipState worst_from = y;
  double worst_l0 = 0.0, worst_l1 = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const int sub = std::max(1, static_cast<int>(std::ceil(std::abs(points[i] - points[i - 1]) / step)));
    double l_prev = points[i - 1];
    for (int k = 1; k <= sub; ++k) {
      const double l = points[i - 1] + (points[i] - points[i - 1]) * k / sub;
      const TipState next = run(base.with_separation(l), y, settle, o);
      const double rate = distance(next, y, omega) / std::abs(l - l_prev);
      if (rate > r.max_rate) {
        r.max_rate = rate;
        r.max_rate_at = l;
        worst_from = y;
        worst_l0 = l_prev;
        worst_l1 = l;
      }
      y = next;
      l_prev = l;
    }
    r.at_points.push_back(y);
  }
  // refine the steepest interval
  const double l_mid = 0.5 * (worst_l0 + worst_l1);
  const TipState mid = run(base.with_separation(l_mid), worst_from, settle, o);
  const TipState end = run(base.with_separation(worst_l1), mid, settle, o);
  const double half = std::abs(l_mid - worst_l0);
  r.refinement_ratio =
      std::max(distance(mid, worst_from, omega), distance(end, mid, omega)) / half / std::max(r.max_rate, 1e-300);
  return r;
}

/// The sweep points of `side` with separations in [lo, hi], in sweep order.
std::vector<const SweepPoint*> points_in(const std::vector<SweepPoint>& side, double lo, double hi) {
  std::vector<const SweepPoint*> out;
  for (const SweepPoint& p : side)
    if (p.separation >= lo - 1e-12 && p.separation <= hi + 1e-12) out.push_back(&p);
  return out;
}

/// No jump on either side; the independent settled ramp over [lo, hi] (approach direction) is continuous (its
/// steepest interval refines like a slope, not a jump) and lands on the sweep's approach orbits.
void expect_continuous(const TappingModel& base, const SweepResult& s, double lo, double hi) {
  EXPECT_TRUE(s.approach_jumps.empty()) << "first approach jump at " << s.approach_jumps.front();
  EXPECT_TRUE(s.retract_jumps.empty()) << "first retract jump at " << s.retract_jumps.front();
  const auto pts = points_in(s.approach, lo, hi);
  ASSERT_GE(pts.size(), 3u);
  std::vector<double> ls;
  for (const SweepPoint* p : pts) ls.push_back(p->separation);
  const double omega = base.drive.frequency;
  const RampResult r = ramp(base, pts.front()->orbit.initial, ls, 0.005 * base.free_amplitude(), 400);
  const double scale = base.free_amplitude();
  EXPECT_LT(r.refinement_ratio, 1.5) << "the settled ramp jumps near l = " << r.max_rate_at;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_LT(distance(r.at_points[i], pts[i]->orbit.initial, omega), 1e-4 * scale) << "at l = " << ls[i];
    EXPECT_TRUE(pts[i]->periodic);
    EXPECT_FALSE(pts[i]->jumped);
  }
}

// Grazing is a continuous (non-smooth) transition for law (10) (K = 10) and law (11) (K_a = 10, K_b = 8) at
// resonance, Q = 100, Γ = 0.2 (free amplitude 20): 41 separations across it, no jump.
TEST(Jumps, NoJumpAtGrazingLinearLaw10) {
  const TappingModel base = make_model(10, 10, 0, 0, 20.0, 1.0);
  const SweepResult s = sweep_instrument(base, 19.2, 20.8, 41);
  expect_continuous(base, s, 19.2, 20.8);
}

TEST(Jumps, NoJumpAtGrazingHysteresisLaw11) {
  const TappingModel base = make_model(10, 8, 0, 0, 20.0, 1.0);
  const SweepResult s = sweep_instrument(base, 19.2, 20.8, 41);
  expect_continuous(base, s, 19.2, 20.8);
}

// Coarse grid along a steep, smooth curve (law 11, Q = 400, free amplitude 80; what `afmkit tapping sweep
// --quality-factor 400 --separation-min 20 --separation-max 100 --points 50` runs): the amplitude falls by ~1.6
// per step below grazing; this used to be listed as four jumps between 77.1 and 72.2.
TEST(Jumps, NoJumpOnCoarseGridAlongSmoothCurve) {
  const TappingModel base = make_model(10, 8, 0, 0, 100.0, 1.0, 400.0);
  const SweepResult s = sweep_instrument(base, 20.0, 100.0, 50);
  EXPECT_TRUE(s.approach_jumps.empty());
  EXPECT_TRUE(s.retract_jumps.empty());
  // approach and retract coincide (no hysteresis), and the independent ramp through 78.8 … 70.6 is continuous
  for (std::size_t i = 0; i < s.approach.size(); ++i)
    EXPECT_NEAR(s.approach[s.approach.size() - 1 - i].metrics.amplitude, s.retract[i].metrics.amplitude, 1e-8 * 80);
  const auto pts = points_in(s.approach, 70.5, 79.0);
  ASSERT_EQ(pts.size(), 6u);
  std::vector<double> ls;
  for (const SweepPoint* p : pts) ls.push_back(p->separation);
  // (closed-form flow for speed: Q = 400 needs ~1500 periods to settle; the ramp uses no shooting or continuation)
  const RampResult r = ramp(base, pts.front()->orbit.initial, ls, 0.2, 1500, SimulationOptions{});
  EXPECT_LT(r.refinement_ratio, 1.5) << "near l = " << r.max_rate_at;
  for (std::size_t i = 0; i < pts.size(); ++i)
    EXPECT_LT(distance(r.at_points[i], pts[i]->orbit.initial, 1.0), 1e-4 * 80) << "at l = " << ls[i];
}

// Law (26), demo case (K_a = 10, K_b = 8, F_a = 0.5, F_b = 1, ω = 0.99): the retract passes grazing (l = A_free
// = 8.998) on the contact branch without a jump and jumps at the fold (≈ 10.1138); the approach jumps at grazing
// (the free branch ends in a corner with the unstable branch). Real jumps stay reported on fine and coarse grids.
TEST(Jumps, DemoCaseKeepsRealJumpsAndNoneAtGrazingOnRetract) {
  const TappingModel base = make_model(10, 8, 0.5, 1, 10.0, 0.99);
  const double l_free = base.free_amplitude();
  for (int points : {9, 17, 81}) {
    const SweepResult s = sweep_instrument(base, 8.4, 10.4, points);
    ASSERT_EQ(s.approach_jumps.size(), 1u) << points << " points";
    ASSERT_EQ(s.retract_jumps.size(), 1u) << points << " points";
    // located where the followed branch ends (SweepOptions::jump_tolerance), whatever the grid: grazing of the
    // free orbit (closed form) and the fold of the contact branch (continuation, 10.1138 to 4 decimals)
    const double tol = SweepOptions{}.jump_tolerance * l_free;
    EXPECT_NEAR(s.approach_jumps[0], l_free, tol) << points << " points";
    EXPECT_NEAR(s.retract_jumps[0], 10.1138, 5e-5 + tol) << points << " points";
  }
  // independent: a slow retract ramp through grazing (8.9 → 9.1) stays on the contact orbit continuously …
  const SweepResult s = sweep_instrument(base, 8.4, 10.4, 81);
  const auto pts = points_in(s.retract, 8.9, 9.1);
  std::vector<double> ls;
  for (const SweepPoint* p : pts) ls.push_back(p->separation);
  const RampResult up = ramp(base, pts.front()->orbit.initial, ls, 0.005, 400);
  EXPECT_LT(up.refinement_ratio, 1.5) << "near l = " << up.max_rate_at;
  for (std::size_t i = 0; i < pts.size(); ++i)
    EXPECT_LT(distance(up.at_points[i], pts[i]->orbit.initial, 0.99), 1e-4 * l_free) << "at l = " << ls[i];
  // … while the approach ramp through grazing (9.1 → 8.9) leaves the free orbit discontinuously
  const auto apts = points_in(s.approach, 8.9, 9.1);
  ls.clear();
  for (const SweepPoint* p : apts) ls.push_back(p->separation);
  const RampResult down = ramp(base, apts.front()->orbit.initial, ls, 0.005, 400);
  EXPECT_GT(down.refinement_ratio, 1.8);
  EXPECT_LT(down.max_rate_at, l_free);
}

TEST(Jumps, FollowBranchStopsAtTheFold) {
  // the demo contact branch followed up from l = 10.0 reaches 10.11 but not 10.12 (fold ≈ 10.1138)
  const TappingModel base = make_model(10, 8, 0.5, 1, 10.0, 0.99);
  const SweepResult s = sweep_instrument(base, 8.4, 10.0, 17);
  const PeriodicOrbit& contact = s.retract.back().orbit;
  ASSERT_GT(contact.stats.impacts, 0);
  const auto at_1011 = follow_branch(base, contact, 10.11);
  ASSERT_TRUE(at_1011.has_value());
  EXPECT_GT(at_1011->stats.impacts, 0);
  EXPECT_TRUE(at_1011->stable);
  // independently periodic
  const auto m = base.with_separation(10.11);
  const TipState once = run(m, at_1011->initial, 1);
  EXPECT_LT(distance(once, at_1011->initial, 0.99), 1e-6 * 10);
  EXPECT_FALSE(follow_branch(base, contact, 10.12).has_value());
  EXPECT_THROW(follow_branch(base, contact, std::nan("")), InvalidParameter);
}

// An explicit list of separations (any order, duplicates) is the same sweep as the grid it holds: approach from
// the largest down, retract from the smallest up.
TEST(Jumps, AListOfSeparationsIsTheSweepOfItsSortedPoints) {
  const TappingModel base = make_model(10, 8, 0, 0, 20.0, 1.0);
  const SweepResult grid = sweep_instrument(base, 18.0, 21.0, 7);
  const SweepResult list = sweep_instrument(base, std::vector<double>{19.5, 21.0, 18.0, 20.5, 18.5, 19.0, 20.0, 18.0});
  ASSERT_EQ(list.approach.size(), grid.approach.size());
  ASSERT_EQ(list.retract.size(), grid.retract.size());
  for (std::size_t i = 0; i < grid.approach.size(); ++i) {
    EXPECT_NEAR(list.approach[i].separation, grid.approach[i].separation, 1e-12);
    EXPECT_NEAR(list.approach[i].metrics.amplitude, grid.approach[i].metrics.amplitude, 1e-9);
    EXPECT_NEAR(list.retract[i].separation, grid.retract[i].separation, 1e-12);
    EXPECT_NEAR(list.retract[i].metrics.amplitude, grid.retract[i].metrics.amplitude, 1e-9);
  }
  EXPECT_GT(list.approach.front().separation, list.approach.back().separation);
  EXPECT_THROW(sweep_instrument(base, std::vector<double>{10.0, 10.0}), afmkit::InvalidParameter);
  EXPECT_THROW(sweep_instrument(base, std::vector<double>{10.0, std::nan("")}), afmkit::InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
