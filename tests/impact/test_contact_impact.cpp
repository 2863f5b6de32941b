// The impact command with a contact-aware table law (docs/force-laws.md#hysteresis): an approach stopped above the
// contact gap by an external force departs on the approach branch (no loss); a touching impact loses the area
// between the branches from its minimum gap up (the same as the velocity-sign rule).
#include <cmath>

#include <gtest/gtest.h>

#include "../tapping_sim/contact_curve.hpp"
#include "afmkit/impact/impact.hpp"
#include "afmkit/impact/laws/table_law.hpp"

using namespace afmkit::impact;

namespace {
ImpactResult run(Hysteresis h, double speed) {
  const ForceLaw law = make_law<TableLaw>(afmkit_test::neck_curve(), false, h);
  // unit masses, gap 20 nm, a constant 1 nN pulling body 2 away: a slow approach turns near 8 nm
  const ImpactProblem p(Body{1.0, 0.0, 0.0}, Body{1.0, 20.0, -speed}, law, ExternalForces{0.0, 1.0, {}, {}});
  ImpactOptions o;
  o.method = ImpactMethod::integrator;
  return simulate_impact(p, o);
}
}  // namespace

TEST(ContactImpact, AnApproachThatStopsAboveTheContactGapLosesNothing) {
  const auto aware = run(Hysteresis::contact, 4.9), seed = run(Hysteresis::velocity, 4.9);
  ASSERT_EQ(aware.outcome, ImpactOutcome::separated);
  ASSERT_EQ(seed.outcome, ImpactOutcome::separated);
  ASSERT_GT(aware.minimum_gap, 1.0);                      // never touched
  ASSERT_LT(aware.minimum_gap, afmkit_test::kPullOff - 1);  // but turned inside the neck range
  EXPECT_EQ(aware.energy_loss_area, 0.0);
  EXPECT_NEAR(aware.restitution, 1.0, 1e-8);
  // the seed's rule: the neck is a friction on the way out
  EXPECT_GT(seed.energy_loss_area, 0.1);
  EXPECT_LT(seed.restitution, 0.99);
}

TEST(ContactImpact, ATouchingImpactLosesTheAreaFromItsMinimumGap) {
  const auto aware = run(Hysteresis::contact, 30.0), seed = run(Hysteresis::velocity, 30.0);
  ASSERT_EQ(aware.outcome, ImpactOutcome::separated);
  ASSERT_LT(aware.minimum_gap, make_law<TableLaw>(afmkit_test::neck_curve()).contact_gap());
  EXPECT_GT(aware.energy_loss_area, 0.0);
  EXPECT_NEAR(aware.energy_loss_area, seed.energy_loss_area, 1e-9 * seed.energy_loss_area);
  EXPECT_NEAR(aware.restitution, seed.restitution, 1e-8);
}

TEST(ContactImpact, AboveTheReleaseGapTheDepartureIsTheApproachBranch) {
  // a 0.02 nN drag difference up to 70 nm, hidden by a 0.03 nN release tolerance: a touching impact from 20 nm
  // loses the area up to the release gap only, and the integrated motion agrees with that balance
  const auto curve = afmkit_test::neck_curve(0.02, 70.0);
  const ForceLaw law = make_law<TableLaw>(curve, false, Hysteresis::contact, 0.03);
  ASSERT_LT(law.release_gap(), 12.0);
  const ImpactProblem p(Body{1.0, 0.0, 0.0}, Body{1.0, 20.0, -30.0}, law, ExternalForces{0.0, 1.0, {}, {}});
  ImpactOptions o;
  o.method = ImpactMethod::integrator;
  const auto r = simulate_impact(p, o);
  ASSERT_EQ(r.outcome, ImpactOutcome::separated);
  ASSERT_LT(r.minimum_gap, law.contact_gap());
  const double area = law.hysteresis_area(r.minimum_gap, law.release_gap());
  EXPECT_NEAR(r.energy_loss_area, area, 1e-12 * area);
  EXPECT_LT(area, law.hysteresis_area(r.minimum_gap, 20.0) - 0.01);  // the drag above d_r is not counted
  EXPECT_LE(std::abs(r.energy_balance_residual), 1e-7 * area);        // the integrated motion agrees
}
