// Separation sweeps and continuation: the hysteresis loop of docs/theory-tapping.md#hb-accuracy, the fold and the
// unstable middle branch, cross-checked with an independent transient of the adaptive integrator and with harmonic
// balance.
#include <cmath>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/observer.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "fixtures.hpp"

namespace afmkit::tapping {
namespace {

using testing::make_model;
using testing::repulsive_model;

// Demo sweep case (docs/theory-tapping.md#hb-accuracy): K_a = 10, K_b = 8, F_a = 0.5, F_b = 1, ω = 0.99 (HB: l_free =
// 8.9982, fold 10.1003)
TappingModel loop_model(double l = 10.0) { return make_model(10, 8, 0.5, 1, l, 0.99); }

class HysteresisSweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { result_ = new SweepResult(sweep_instrument(loop_model(), 8.8, 10.4, 81)); }
  static void TearDownTestSuite() { delete result_; }
  static SweepResult* result_;
};
SweepResult* HysteresisSweep::result_ = nullptr;

TEST_F(HysteresisSweep, ApproachJumpsIntoContactAtGrazing) {
  const double l_free = loop_model().free_amplitude();  // 8.9982: the free orbit starts touching (ext. E7)
  ASSERT_EQ(result_->approach_jumps.size(), 1u);
  const double jump = result_->approach_jumps[0];
  EXPECT_NEAR(jump, l_free, SweepOptions{}.jump_tolerance * l_free);  // located at grazing, not at a grid point
  for (const SweepPoint& p : result_->approach) {
    if (p.separation > l_free) {  // free response above grazing
      EXPECT_NEAR(p.metrics.amplitude, l_free, 1e-9);
    }
    EXPECT_TRUE(p.orbit.stable);
  }
}

TEST_F(HysteresisSweep, RetractStaysInContactUpToTheFold) {
  ASSERT_EQ(result_->retract_jumps.size(), 1u);
  // The reference of docs/theory-tapping.md#hb-accuracy (fixed-step RK4, 120 periods per step) reports the jump at l ∈
  // (10.12, 10.14]; the exact flow puts the fold at l* ≈ 10.1138, where the sweep locates the jump (see the
  // adaptive cross-check below).
  EXPECT_NEAR(result_->retract_jumps[0], 10.1138, 5e-5 + SweepOptions{}.jump_tolerance * loop_model().free_amplitude());
  const double l_free = loop_model().free_amplitude();
  for (const SweepPoint& p : result_->retract) {
    EXPECT_TRUE(p.orbit.stable);
    if (p.separation < result_->retract_jumps[0] - 1e-9) {
      EXPECT_LT(p.metrics.min_gap, 0.0);  // contact branch
      if (p.separation > l_free) {  // above the free amplitude
        EXPECT_GT(p.metrics.amplitude, l_free + 1e-3);
      }
      // HB tracks this branch to within 0.3 % (docs/theory-tapping.md#hb-accuracy: 0.22 % for the RK4 simulation)
      EXPECT_NEAR(p.hb_amplitude, p.metrics.amplitude, 3e-3 * p.metrics.amplitude);
    } else {
      EXPECT_NEAR(p.metrics.amplitude, l_free, 1e-9);
    }
  }
}

TEST_F(HysteresisSweep, LoopIsClosedAndEnergyBalanced) {
  const auto& a = result_->approach;
  const auto& r = result_->retract;
  ASSERT_EQ(a.size(), 81u);
  ASSERT_EQ(r.size(), 81u);
  EXPECT_DOUBLE_EQ(a.front().separation, 10.4);
  EXPECT_DOUBLE_EQ(a.back().separation, 8.8);
  EXPECT_DOUBLE_EQ(r.front().separation, 8.8);
  EXPECT_NEAR(a.back().metrics.amplitude, r.front().metrics.amplitude, 1e-12);
  for (const auto* side : {&a, &r})
    for (const SweepPoint& p : *side)
      EXPECT_NEAR(p.metrics.drive_work, p.metrics.energy_dissipated(), 1e-9 * p.metrics.drive_work);
}

TEST(Sweep, FoldConfirmedByAdaptiveIntegratorTransient) {
  // Independent of the closed form and of shooting: from the contact orbit at l = 10.11 the adaptive
  // integrator keeps tapping at l = 10.11 but leaves contact for good at l = 10.12.
  // (HB has no contact solution at 10.11 — its fold is at 10.100 — so follow the branch up from l = 10.)
  const auto found = find_orbits(loop_model(10.0));
  ASSERT_EQ(found.orbits.size(), 3u);
  PeriodicOrbit top = found.orbits.back().orbit;
  // near the fold the upper and middle orbits differ by ~1e-3 only: small steps keep Newton on the upper one
  for (int k = 1; k <= 110; ++k) top = shoot(loop_model(10.0 + 0.001 * k), top.initial, 1);
  ASSERT_TRUE(top.stable);
  ASSERT_GT(top.stats.impacts, 0);
  SimulationOptions adaptive;
  adaptive.integrator = Integrator::adaptive;
  for (double l : {10.11, 10.12}) {
    const auto m = loop_model(l);
    TipState y = top.initial;
    long contacts_last = 0;
    for (int k = 0; k < 120; ++k) {
      const auto r = simulate(m, 0.0, y, m.period(), adaptive);
      y = r.state;
      if (k >= 100) contacts_last += r.stats.impacts;
    }
    if (l < 10.115)
      EXPECT_EQ(contacts_last, 20);
    else
      EXPECT_EQ(contacts_last, 0);
  }
}

TEST(Sweep, ContinuationPassesTheFoldWithUnstableMiddleBranch) {
  const auto model = loop_model();
  const ContinuationResult c = sweep_continuation(model, 8.8, 10.4);
  ASSERT_EQ(c.folds.size(), 1u);
  EXPECT_NEAR(c.folds[0].separation, 10.1138, 5e-4);
  EXPECT_TRUE(c.folds[0].separation_maximum);  // the contact branch turns back at its largest l
  ASSERT_EQ(c.grazing.size(), 1u);
  EXPECT_NEAR(c.grazing[0], model.free_amplitude(), 1e-9);
  // stable contact branch up to the fold, unstable branch back down to grazing, stable free branch after
  int phase = 0, stable_after = 0, unstable = 0;
  for (const SweepPoint& p : c.points) {
    EXPECT_EQ(p.direction, SweepDirection::continuation);
    if (phase == 0 && !p.orbit.stable) phase = 1;
    if (phase == 1 && p.orbit.stable) phase = 2;
    if (phase == 0) {
      EXPECT_LT(p.separation, c.folds[0].separation + 1e-9);
    }
    if (phase == 1) {
      ++unstable;
      EXPECT_GT(p.separation, model.free_amplitude());
      EXPECT_GT(p.orbit.floquet_max, 1.0);
    }
    if (phase == 2) {
      ++stable_after;
      EXPECT_TRUE(p.orbit.stable);
      EXPECT_NEAR(p.metrics.amplitude, model.free_amplitude(), 1e-9);
    }
  }
  EXPECT_GT(unstable, 5);
  EXPECT_GT(stable_after, 2);
  EXPECT_EQ(c.stop_reason, "left range");
  // every continuation point is a periodic orbit: an independent one-period simulation closes it
  for (const SweepPoint& p : c.points) {
    const auto m = model.with_separation(p.separation);
    const auto r = simulate(m, 0.0, p.orbit.initial, m.period());
    EXPECT_NEAR(r.state.position, p.orbit.initial.position, 1e-7 * std::max(1.0, p.orbit.floquet_max));
  }
  // the middle branch lies between the two stable orbits at the same separation
  const auto found = find_orbits(model.with_separation(9.6));
  ASSERT_EQ(found.orbits.size(), 3u);
  const double middle = found.orbits[1].metrics.amplitude;
  bool matched = false;
  for (const SweepPoint& p : c.points)
    if (!p.orbit.stable && std::abs(p.separation - 9.6) < 0.05)
      matched = std::abs(p.metrics.amplitude - middle) < 0.05 * (found.orbits[2].metrics.amplitude - middle + 1e-3) + 0.05;
  EXPECT_TRUE(matched);
}

TEST(Sweep, GridMatchesSerialSearch) {
  const auto model = loop_model();
  const std::vector<double> ls{9.0, 9.6, 10.3};
  OrbitSearchOptions o;
  const auto grid = sweep_grid(model, ls, o);
  ASSERT_EQ(grid.size(), ls.size());
  for (std::size_t i = 0; i < ls.size(); ++i) {
    OrbitSearchOptions serial;
    serial.parallel = false;
    const auto one = find_orbits(model.with_separation(ls[i]), serial);
    ASSERT_EQ(grid[i].orbits.size(), one.orbits.size());
    for (std::size_t k = 0; k < one.orbits.size(); ++k)
      EXPECT_NEAR(grid[i].orbits[k].metrics.amplitude, one.orbits[k].metrics.amplitude, 1e-9);
  }
}

TEST(Sweep, RejectsBadRanges) {
  const auto model = repulsive_model();
  EXPECT_THROW(sweep_instrument(model, 10.0, 5.0, 10), InvalidParameter);
  EXPECT_THROW(sweep_instrument(model, 5.0, 5.0, 10), InvalidParameter);
  EXPECT_THROW(sweep_instrument(model, 5.0, 10.0, 1), InvalidParameter);
  EXPECT_THROW(sweep_instrument(model, std::nan(""), 10.0, 10), InvalidParameter);
  EXPECT_THROW(sweep_continuation(model, 10.0, 5.0), InvalidParameter);
  EXPECT_THROW(sweep_grid(model, {1.0, std::numeric_limits<double>::infinity()}), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
