// SweepOptions::retract = false: the approach-only sweep is the approach of the full sweep, orbit for orbit, with
// no retract pass and no retract jump; the harmonic balance shared by both directions gives each point the HB
// solution an independent evaluation at its separation gives (attach_harmonic_balance).
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "afmkit/tapping/sweep.hpp"
#include "fixtures.hpp"

namespace afmkit::tapping {
namespace {

// The demo's hysteresis case (jumps on approach and on retract): K_a = 10, K_b = 8, F_a = 0.5, F_b = 1, ω = 0.99.
TappingModel directions_loop_model() { return testing::make_model(10, 8, 0.5, 1, 10.0, 0.99); }

bool directions_same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

TEST(SweepDirections, ApproachOnlyIsTheApproachOfTheFullSweep) {
  SweepOptions both;
  both.parallel = false;
  SweepOptions approach = both;
  approach.retract = false;
  const SweepResult full = sweep_instrument(directions_loop_model(), 8.8, 10.4, 33, both);
  const SweepResult half = sweep_instrument(directions_loop_model(), 8.8, 10.4, 33, approach);
  ASSERT_FALSE(full.retract.empty());
  ASSERT_FALSE(full.retract_jumps.empty()) << "the case has a retract jump to leave out";
  EXPECT_TRUE(half.retract.empty());
  EXPECT_TRUE(half.retract_jumps.empty());
  ASSERT_EQ(half.approach.size(), full.approach.size());
  for (std::size_t k = 0; k < half.approach.size(); ++k) {
    const SweepPoint &a = half.approach[k], &b = full.approach[k];
    EXPECT_TRUE(directions_same_bits(a.separation, b.separation));
    EXPECT_TRUE(directions_same_bits(a.metrics.amplitude, b.metrics.amplitude)) << "point " << k;
    EXPECT_TRUE(directions_same_bits(a.metrics.phase, b.metrics.phase)) << "point " << k;
    EXPECT_TRUE(directions_same_bits(a.hb_amplitude, b.hb_amplitude) || (std::isnan(a.hb_amplitude) && std::isnan(b.hb_amplitude)));
    EXPECT_EQ(a.jumped, b.jumped);
  }
  EXPECT_EQ(half.approach_jumps, full.approach_jumps);
  for (const SweepJump& j : half.jumps) EXPECT_EQ(j.direction, SweepDirection::approach);
  // one harmonic balance for both directions: each point's HB as evaluated on its own
  for (const auto* points : {&full.approach, &full.retract})
    for (const SweepPoint& p : *points) {
      SweepPoint own = p;
      own.hb_amplitude = own.hb_offset = own.hb_phase = std::nan("");
      own.hb_solutions = 0;
      attach_harmonic_balance(directions_loop_model(), own);
      EXPECT_EQ(own.hb_solutions, p.hb_solutions) << "l = " << p.separation;
      if (own.hb_solutions > 0) {
        EXPECT_NEAR(own.hb_amplitude, p.hb_amplitude, 1e-9 * std::abs(p.hb_amplitude));
      }
    }
}

TEST(SweepDirections, WithoutHarmonicBalanceTheHbFieldsStayEmpty) {
  SweepOptions o;
  o.parallel = false;
  o.harmonic_balance = false;
  o.retract = false;
  const SweepResult r = sweep_instrument(directions_loop_model(), 9.5, 10.4, 5, o);
  for (const SweepPoint& p : r.approach) {
    EXPECT_TRUE(std::isnan(p.hb_amplitude));
    EXPECT_EQ(p.hb_solutions, 0);
  }
}

}  // namespace
}  // namespace afmkit::tapping
