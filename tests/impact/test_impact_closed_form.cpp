// Closed-form impacts with piecewise-linear hysteresis (seed-1 eqs. 2, 3, 6, 11, 26, ext. E0;
// docs/theory-tapping.md#impact).
#include <gtest/gtest.h>

#include <cmath>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/impact.hpp"
#include "reference_rk4.hpp"

using namespace afmkit::impact;

namespace {
double momentum(const Body& a, const Body& b) { return a.mass * a.velocity + b.mass * b.velocity; }
}  // namespace

TEST(ImpactClosedForm, RestitutionIsSqrtOfStiffnessRatio) {
  // seed-1 ext. E0: e = √(K_b/K_a), independent of masses and speed; loss = ½(K_a − K_b)δ² (eq. 6) =
  // (1 − e²) μ/2 v² (eq. 3) = direct kinetic-energy difference.
  for (double ratio : {1.0, 1.25, 4.0, 100.0}) {
    for (auto [m1, m2, speed] : {std::tuple{1.0, 1.0, 1.0}, std::tuple{3.0, 0.2, 2.5}, std::tuple{1e-11, 1e-9, 1e6}}) {
      const double ka = 7.0, kb = ka / ratio;
      const auto problem = ImpactProblem::head_on(m1, m2, speed, 0.5, PiecewiseLinearLaw::linear_hysteresis(ka, kb));
      const ImpactResult r = simulate_impact(problem);
      ASSERT_EQ(r.outcome, ImpactOutcome::separated);
      EXPECT_EQ(r.method, "closed_form");
      const double e = std::sqrt(kb / ka);
      EXPECT_NEAR(r.restitution, e, 1e-14) << ratio;
      const double mu = m1 * m2 / (m1 + m2);
      const double ke = 0.5 * mu * speed * speed;
      const double delta = -r.minimum_gap;
      EXPECT_NEAR(delta, speed * std::sqrt(mu / ka), 1e-13 * delta);  // ½ μ v² = ½ K_a δ²
      const double loss = 0.5 * (ka - kb) * delta * delta;
      EXPECT_NEAR(r.kinetic_energy_loss, loss, 1e-12 * ke);
      EXPECT_NEAR(r.energy_loss_area, loss, 1e-12 * ke);
      EXPECT_NEAR(r.energy_loss_restitution, (1 - e * e) * ke, 1e-12 * ke);
      EXPECT_NEAR(r.energy_loss_restitution, restitution_energy_loss(m1, m2, -speed, e), 1e-12 * ke);
      // momentum conserved (isolated)
      const double p0 = momentum(problem.body1(), problem.body2()), p1 = momentum(r.body1_after, r.body2_after);
      EXPECT_NEAR(p1, p0, 1e-14 * (m1 + m2) * speed);
      // gap back to d(t_s), departing at e·v
      EXPECT_NEAR(r.body2_after.position - r.body1_after.position, 0.5, 1e-14);
      EXPECT_NEAR(r.departure_gap_rate, e * speed, 1e-13 * speed);
      // contact: half periods of the two springs, π/2 √(μ/K_a) + π/2 √(μ/K_b)
      EXPECT_NEAR(r.contact_duration, M_PI / 2 * (std::sqrt(mu / ka) + std::sqrt(mu / kb)),
                  1e-13 * r.contact_duration);
      EXPECT_NEAR(r.contact_start, 0.5 / speed, 1e-14 * r.end_time);
      EXPECT_NEAR(r.peak_force, ka * delta, 1e-13 * ka * delta);
      EXPECT_NEAR(r.max_penetration, delta, 0);
    }
  }
}

TEST(ImpactClosedForm, DepartureStiffnessForRestitutionGivesThatRestitution) {
  for (double target : {0.1, 0.5, 0.8, 0.999}) {
    const double ka = 40.0;
    const double kb = PiecewiseLinearLaw::departure_stiffness_for_restitution(ka, target);
    const auto r =
        simulate_impact(ImpactProblem::head_on(2.0, 5.0, 0.3, 0.0, PiecewiseLinearLaw::linear_hysteresis(ka, kb)));
    EXPECT_NEAR(r.restitution, target, 1e-14);
  }
}

TEST(ImpactClosedForm, MatchesIndependentRk4) {
  // same impact: closed form vs fixed-step RK4 with bisection-located events (tests/impact/reference_rk4.hpp)
  struct Case {
    double ka, kb, fa, fb, m1, m2, speed, gap;
  };
  for (const Case& c : {Case{10, 8, 0, 0, 1, 1, 1, 0.2}, Case{100, 25, 0.3, 0.9, 0.5, 2, 3, 0.1},
                        Case{4, 1, 0.1, 0.4, 1, 4, 2, -0.05}}) {
    const PiecewiseLinearLaw law(c.ka, c.kb, c.fa, c.fb);
    const auto r = simulate_impact(ImpactProblem::head_on(c.m1, c.m2, c.speed, c.gap, law));
    const double mu = c.m1 * c.m2 / (c.m1 + c.m2);
    const auto ref = afmkit_test::reference_impact(
        [&](double d, bool in) { return in ? -(c.fa + c.ka * d) : 0.0; },
        [&](double d, bool in) { return in ? -(c.fb + c.kb * d) : 0.0; }, mu, 0.0, c.gap, -c.speed, 0.0, 1e-4);
    ASSERT_TRUE(ref.separated);
    ASSERT_EQ(r.outcome, ImpactOutcome::separated);
    EXPECT_NEAR(r.minimum_gap, ref.minimum_gap, 1e-10);
    EXPECT_NEAR(r.minimum_time, ref.minimum_time, 1e-10);
    EXPECT_NEAR(r.end_time, ref.end_time, 1e-10);
    EXPECT_NEAR(r.departure_gap_rate, ref.exit_rate, 1e-10 * c.speed);
  }
}

TEST(ImpactClosedForm, AdhesionLossAndCaptureFollowTheEnergyBalance) {
  // eq. (26) law, isolated, start at the contact edge: approach ½μv² + F_a δ = ½K_a δ² gives δ; the loss is
  // the area (F_b − F_a)δ + ½(K_a − K_b)δ²; the bodies separate iff it is below ½μv², then e² = 1 − loss/KE.
  const double ka = 10, kb = 8, fa = 0.3, fb = 0.9, m1 = 1.0, m2 = 1.0, mu = 0.5;
  const PiecewiseLinearLaw law(ka, kb, fa, fb);
  for (double speed : {0.05, 0.2, 0.3, 0.5, 2.0}) {
    const double ke = 0.5 * mu * speed * speed;
    const double delta = (fa + std::sqrt(fa * fa + ka * mu * speed * speed)) / ka;
    const double area = (fb - fa) * delta + 0.5 * (ka - kb) * delta * delta;
    const auto r = simulate_impact(ImpactProblem::head_on(m1, m2, speed, 0.0, law));
    EXPECT_NEAR(-r.minimum_gap, delta, 1e-14);
    if (area < ke) {
      ASSERT_EQ(r.outcome, ImpactOutcome::separated) << speed;
      EXPECT_NEAR(r.restitution, std::sqrt(1 - area / ke), 1e-12);
      EXPECT_NEAR(r.energy_loss_area, area, 1e-13);
      EXPECT_NEAR(r.kinetic_energy_loss, area, 1e-13);
      EXPECT_NEAR(r.min_force, -fb, 1e-15);  // pull-off at the edge on the departure branch
    } else {
      EXPECT_EQ(r.outcome, ImpactOutcome::captured) << speed;
      EXPECT_TRUE(std::isnan(r.restitution));
      EXPECT_FALSE(r.capture_reason.empty());
    }
  }
}

TEST(ImpactClosedForm, StickingWhenDepartureBranchCannotPushApart) {
  // K_b δ < F_b: at the minimum gap the departure force −F_b + K_b δ is attractive -> stuck (Filippov)
  const auto r = simulate_impact(
      ImpactProblem::head_on(1.0, 1.0, 0.1, 0.0, PiecewiseLinearLaw(1.0, 0.01, 0.0, 0.5)), {.history_points = 5});
  EXPECT_EQ(r.outcome, ImpactOutcome::captured);
  EXPECT_NE(r.capture_reason.find("stuck"), std::string::npos);
  EXPECT_NEAR(r.end_time, r.minimum_time, 0);
  EXPECT_NEAR(r.body1_after.velocity, r.body2_after.velocity, 1e-15);
}

TEST(ImpactClosedForm, ApproachWithoutRepulsionIsNumericalFailure) {
  // K_a = 0 with adhesion: the approach branch only pulls, no minimum gap exists
  EXPECT_THROW(simulate_impact(ImpactProblem::head_on(1, 1, 1, 0.1, PiecewiseLinearLaw(0.0, 0.0, 0.2, 0.2))),
               afmkit::NumericalFailure);
}

TEST(ImpactClosedForm, ConstantExternalForcesMatchRk4AndImpulse) {
  // forces pushing the bodies apart (g = F2/m2 − F1/m1 > 0) act during flight and contact: compare with RK4
  const PiecewiseLinearLaw law(50.0, 30.0);
  const Body b1{2.0, 0.0, 1.0}, b2{1.0, 0.3, -1.0};
  ExternalForces ext;
  ext.on_body1 = -0.4;  // pushes body 1 away from body 2
  ext.on_body2 = 0.1;   // pushes body 2 away from body 1: g = 0.1 + 0.2 = 0.3 > 0
  const ImpactProblem problem(b1, b2, law, ext);
  const auto r = simulate_impact(problem);
  ASSERT_EQ(r.outcome, ImpactOutcome::separated);
  const double mu = 2.0 / 3.0, g = 0.1 / 1.0 - (-0.4) / 2.0;
  const auto ref = afmkit_test::reference_impact([](double d, bool in) { return in ? -50.0 * d : 0.0; },
                                                 [](double d, bool in) { return in ? -30.0 * d : 0.0; }, mu, g,
                                                 0.3, -2.0, 0.0, 1e-4);
  ASSERT_TRUE(ref.separated);
  EXPECT_NEAR(r.end_time, ref.end_time, 1e-10);
  EXPECT_NEAR(r.departure_gap_rate, ref.exit_rate, 1e-10);
  // momentum change = impulse of the external forces
  const double dp = momentum(r.body1_after, r.body2_after) - momentum(b1, b2);
  EXPECT_NEAR(dp, (ext.on_body1 + ext.on_body2) * r.end_time, 1e-14);
}

TEST(ImpactClosedForm, RepulsiveExternalForceTurnsBeforeContact) {
  // strong push apart: the bodies turn back in free flight, no contact, e = 1 (no loss)
  ExternalForces ext;
  ext.on_body2 = 10.0;
  const auto r = simulate_impact(ImpactProblem({1, 0, 0}, {1, 1, -1}, PiecewiseLinearLaw(5, 1), ext));
  EXPECT_EQ(r.outcome, ImpactOutcome::separated);
  EXPECT_FALSE(r.contact);
  EXPECT_EQ(r.contact_duration, 0.0);
  EXPECT_NEAR(r.minimum_gap, 1 - 1.0 / (2 * 10.0), 1e-15);  // d̈ = 10: d_min = d0 − v²/(2 g)
  EXPECT_NEAR(r.restitution, 1.0, 1e-15);
}

TEST(ImpactClosedForm, HistoryIsConsistent) {
  const auto law = PiecewiseLinearLaw::linear_hysteresis(10, 4);
  const auto r = simulate_impact(ImpactProblem::head_on(1, 3, 2, 0.4, law), {.history_points = 101});
  ASSERT_GE(r.history.size(), 101u);
  EXPECT_EQ(r.history.front().time, 0.0);
  EXPECT_EQ(r.history.back().time, r.end_time);
  int rows_at_minimum = 0;
  for (std::size_t i = 0; i < r.history.size(); ++i) {
    const auto& s = r.history[i];
    if (i) {
      EXPECT_GE(s.time, r.history[i - 1].time);
    }
    EXPECT_NEAR(s.gap, s.position2 - s.position1, 1e-14);
    EXPECT_NEAR(s.gap_rate, s.velocity2 - s.velocity1, 1e-13);
    EXPECT_GE(s.gap, r.minimum_gap - 1e-15);
    EXPECT_NEAR(1 * s.velocity1 + 3 * s.velocity2, 0.0, 1e-13);  // centre of mass at rest
    if (s.time == r.minimum_time) ++rows_at_minimum;
  }
  EXPECT_EQ(rows_at_minimum, 2);  // H_a and H_b at t̄
}

TEST(ImpactProblem, BadInputNamesTheParameter) {
  const ForceLaw law = PiecewiseLinearLaw::linear_repulsive(1.0);
  auto expect_param = [](auto&& make, const char* name) {
    try {
      make();
      ADD_FAILURE() << "no throw for " << name;
    } catch (const afmkit::InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), name);
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos);
    }
  };
  expect_param([&] { ImpactProblem({0.0, 0, 1}, {1, 1, 0}, law); }, "mass1");
  expect_param([&] { ImpactProblem({1, 0, 1}, {-2, 1, 0}, law); }, "mass2");
  expect_param([&] { ImpactProblem({1, NAN, 1}, {1, 1, 0}, law); }, "position1");
  expect_param([&] { ImpactProblem({1, 0, 1}, {1, 1, INFINITY}, law); }, "velocity2");
  expect_param([&] { ImpactProblem({1, 0, 0}, {1, 1, 0}, law); }, "relative_velocity");   // not approaching
  expect_param([&] { ImpactProblem({1, 0, -1}, {1, 1, 1}, law); }, "relative_velocity");  // separating
  expect_param([&] { ImpactProblem::head_on(1, 1, 0.0, 1, law); }, "approach_speed");
  expect_param([&] { ImpactProblem({1, 0, 1}, {1, 1, 0}, law, ExternalForces{NAN, 0, {}, {}}); }, "force1");
  const auto ok = ImpactProblem::head_on(1, 1, 1, 0, law);
  expect_param([&] { simulate_impact(ok, {.relative_tolerance = 0}); }, "relative_tolerance");
  expect_param([&] { simulate_impact(ok, {.history_points = 1}); }, "history_points");
  expect_param([&] { simulate_impact(ok, {.max_steps = 0}); }, "max_steps");
  const auto dmt = ImpactProblem::head_on(1, 1, 1, 1, DmtLaw(1, 1, 10, 6e-20, 6e-20, 0.165));
  expect_param([&] { simulate_impact(dmt, {.method = ImpactMethod::closed_form}); }, "method");
  expect_param([&] { hysteresis_energy_loss(law, 1.0, 0.0); }, "minimum_gap");
}
