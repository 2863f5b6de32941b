// Time-domain simulation: the exact closed-form stepper against the adaptive Dormand–Prince stepper with event
// location (an independent integration of the same equations), sensitivities against difference quotients,
// sticking, budgets and input validation.
#include <cmath>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/tapping/observer.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/simulation.hpp"
#include "afmkit/tapping/units.hpp"
#include "fixtures.hpp"

namespace afmkit::tapping {
namespace {

using testing::attractive_model;
using testing::make_model;
using testing::repulsive_model;

SimulationOptions tight_adaptive() {
  SimulationOptions o;
  o.integrator = Integrator::adaptive;
  o.relative_tolerance = 1e-12;
  o.absolute_tolerance = 1e-13;
  return o;
}

void expect_same_trajectory(const TappingModel& model, double periods) {
  const TipState start = free_response_state(model);
  const double t_end = periods * model.period();
  EventRecorder exact_events, adaptive_events;
  const auto exact = simulate(model, 0.0, start, t_end, {}, &exact_events);
  const auto adaptive = simulate(model, 0.0, start, t_end, tight_adaptive(), &adaptive_events);
  ASSERT_GT(exact.stats.impacts, 0);
  EXPECT_EQ(exact.stats.impacts, adaptive.stats.impacts);
  ASSERT_EQ(exact_events.events().size(), adaptive_events.events().size());
  for (std::size_t i = 0; i < exact_events.events().size(); ++i) {
    const Event& a = exact_events.events()[i];
    const Event& b = adaptive_events.events()[i];
    EXPECT_EQ(a.guard.kind, b.guard.kind);
    EXPECT_EQ(a.after, b.after);
    EXPECT_NEAR(a.time, b.time, 1e-8) << "event " << i;
  }
  EXPECT_NEAR(exact.state.position, adaptive.state.position, 1e-8);
  EXPECT_NEAR(exact.state.velocity, adaptive.state.velocity, 1e-8);
}

TEST(Simulation, ClosedFormMatchesAdaptiveRepulsive) { expect_same_trajectory(repulsive_model(10.0), 6); }
TEST(Simulation, ClosedFormMatchesAdaptiveAttractive) { expect_same_trajectory(attractive_model(10.0), 6); }
TEST(Simulation, ClosedFormMatchesAdaptiveDeepContact) { expect_same_trajectory(repulsive_model(2.0), 4); }

TEST(Simulation, FreeResponseIsExactlyPeriodicWithoutContact) {
  const auto model = repulsive_model(30.0);  // free amplitude 20 < 30: never touches
  const TipState start = free_response_state(model);
  const auto r = simulate(model, 0.0, start, 3 * model.period());
  EXPECT_EQ(r.stats.events, 0);
  EXPECT_NEAR(r.state.position, start.position, 1e-12);
  EXPECT_NEAR(r.state.velocity, start.velocity, 1e-12);
}

Eigen::Matrix3d difference_jacobian(const TappingModel& model, TipState s, double t_end, const SimulationOptions& o,
                                    double h = 1e-6) {
  Eigen::Matrix3d j;
  for (int c = 0; c < 3; ++c) {
    TipState p = s, m = s;
    double lp = model.separation, lm = model.separation;
    if (c == 0) p.position += h, m.position -= h;
    if (c == 1) p.velocity += h, m.velocity -= h;
    if (c == 2) lp += h, lm -= h;
    const auto rp = simulate(model.with_separation(lp), 0.0, p, t_end, o);
    const auto rm = simulate(model.with_separation(lm), 0.0, m, t_end, o);
    j(0, c) = (rp.state.position - rm.state.position) / (2 * h);
    j(1, c) = (rp.state.velocity - rm.state.velocity) / (2 * h);
    j(2, c) = c == 2 ? 1.0 : 0.0;
  }
  return j;
}

TEST(Simulation, SensitivityMatchesDifferenceQuotients) {
  for (const auto& model : {repulsive_model(10.0), attractive_model(9.0)}) {
    SimulationOptions o;
    o.sensitivity = true;
    const TipState s = free_response_state(model);
    const double t_end = 1.5 * model.period();
    const auto r = simulate(model, 0.0, s, t_end, o);
    ASSERT_GT(r.stats.impacts, 0);
    const Eigen::Matrix3d fd = difference_jacobian(model, s, t_end, {});
    EXPECT_LT((r.sensitivity - fd).cwiseAbs().maxCoeff(), 1e-6 * fd.cwiseAbs().maxCoeff()) << r.sensitivity << "\n"
                                                                                            << fd;
    // the adaptive stepper's variational equations + saltation matrices agree as well
    SimulationOptions oa = tight_adaptive();
    oa.sensitivity = true;
    const auto ra = simulate(model, 0.0, s, t_end, oa);
    EXPECT_LT((ra.sensitivity - r.sensitivity).cwiseAbs().maxCoeff(), 1e-6 * fd.cwiseAbs().maxCoeff());
  }
}

TEST(Simulation, SensitivitiesOfADenseTableAreControlledRelativeToTheirFloor) {
  // a reconstructed law: 1000 knots over 2 nm (an exponential force with a ripple, as noise leaves it), PCHIP: C¹,
  // so the variational equations' right-hand side (the slope) is only C⁰ at every knot. Their entries are held
  // relative to max(|entry|, 1) (as DOP853 holds them), not to their own possibly tiny size: then one period with
  // sensitivities takes ~4 times the steps of the orbit alone here (18 times when an entry near 0 was held to
  // the absolute tolerance), and the sensitivities still match those of a tight integration and difference quotients.
  impact::ForceCurve curve;
  curve.origin = "dense table";
  for (int i = 0; i < 1000; ++i) {
    const double d = 0.05 + 2.0 * i / 999.0;
    curve.approach_gap.push_back(d);
    curve.approach_force.push_back(-std::exp(-d / 0.1) + 1e-4 * std::sin(7.0 * i));
  }
  curve.retract_gap = curve.approach_gap;
  curve.retract_force = curve.approach_force;
  const PhysicalCantilever pc(1800.0, 25.0, 1e4, 0.5, 1.0);
  const TappingModel model(pc.cantilever(), pc.drive(),
                           pc.normalised_law(impact::make_law<impact::TableLaw>(curve, true)), 0.6);
  const TipState s = free_response_state(model);
  const double t_end = model.period();
  SimulationOptions o;
  const auto plain = simulate(model, 0.0, s, t_end, o);
  o.sensitivity = true;
  const auto with = simulate(model, 0.0, s, t_end, o);
  EXPECT_LT(with.stats.steps, 15 * plain.stats.steps) << with.stats.steps << " vs " << plain.stats.steps;
  // against the sensitivities integrated 100 times more tightly, and central differences of the map (a wide step:
  // the adaptive map is only as smooth as its tolerance)
  SimulationOptions tight;
  tight.relative_tolerance = 1e-12;
  tight.absolute_tolerance = 1e-14;
  tight.sensitivity = true;
  const Eigen::Matrix3d reference = simulate(model, 0.0, s, t_end, tight).sensitivity;
  EXPECT_LT((with.sensitivity - reference).cwiseAbs().maxCoeff(), 1e-7) << with.sensitivity << "\n" << reference;
  tight.sensitivity = false;
  const Eigen::Matrix3d fd = difference_jacobian(model, s, t_end, tight, 1e-4);
  EXPECT_LT((with.sensitivity - fd).cwiseAbs().maxCoeff(), 1e-6) << with.sensitivity << "\n" << fd;
}

TEST(Simulation, SensitivitiesOfASmoothLawTakeFewMoreStepsThanTheStateAndMatchATightRun) {
  // pyDAMPF's DMT + vdW case touching the sample (DOP853): the state is held as the run without sensitivities holds
  // it, the sensitivities to 10 times the tolerance relative to the identity (held to the tolerance itself they
  // took 1.72 times the steps of the state here, 1.47 times now)
  const PhysicalCantilever pc(40.0, 300.0, 400.0, 10.0, 1.0);
  const impact::DmtLaw dmt(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165);
  const TappingModel model(pc.cantilever(), pc.drive(), pc.normalised_law(dmt), 6.0);
  const TipState s = free_response_state(model);
  SimulationOptions o;
  o.relative_tolerance = 1e-10;
  o.absolute_tolerance = 1e-11;
  const auto plain = simulate(model, 0.0, s, model.period(), o);
  ASSERT_GE(plain.stats.impacts, 1);  // (it touches)
  o.sensitivity = true;
  const auto with = simulate(model, 0.0, s, model.period(), o);
  EXPECT_LT(with.stats.steps, 1.6 * plain.stats.steps) << with.stats.steps << " vs " << plain.stats.steps;
  const double scale = std::max(std::abs(plain.state.position), std::abs(plain.state.velocity));
  EXPECT_NEAR(with.state.position, plain.state.position, 1e-9 * scale);
  EXPECT_NEAR(with.state.velocity, plain.state.velocity, 1e-9 * scale);
  SimulationOptions tight = o;
  tight.relative_tolerance = 1e-13;
  tight.absolute_tolerance = 1e-14;
  const Eigen::Matrix3d reference = simulate(model, 0.0, s, model.period(), tight).sensitivity;
  EXPECT_LT((with.sensitivity - reference).cwiseAbs().maxCoeff(), 1e-7 * reference.cwiseAbs().maxCoeff())
      << with.sensitivity << "\n" << reference;
}

TEST(Simulation, EventBudgetExhaustedIsNumericalFailure) {
  SimulationOptions o;
  o.max_events = 3;
  const auto model = repulsive_model(10.0);
  EXPECT_THROW(simulate(model, 0.0, free_response_state(model), 10 * model.period(), o), NumericalFailure);
}

TEST(Simulation, RejectsBadInput) {
  const auto model = repulsive_model(10.0);
  EXPECT_THROW(simulate(model, 1.0, {0, 0}, 0.5), InvalidParameter);
  EXPECT_THROW(simulate(model, 0.0, {std::nan(""), 0}, 1.0), InvalidParameter);
  SimulationOptions o;
  o.max_step_fraction = 0.0;
  EXPECT_THROW(simulate(model, 0.0, {0, 0}, 1.0, o), InvalidParameter);
  const TappingModel dmt(Cantilever(1.0, 100.0), Drive(0.2, 1.0),
                         impact::ForceLaw(impact::DmtLaw(1.0, 1.0, 10.0, 1e-19, 1e-19, 0.2)), 10.0);
  SimulationOptions cf;
  cf.integrator = Integrator::closed_form;
  EXPECT_THROW(simulate(dmt, 0.0, {0, 0}, 1.0, cf), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping

namespace afmkit::tapping {
namespace {

// The same hysteresis law given as a custom callable (no closed form: the adaptive path with the generic
// region/branch logic) must reproduce the closed-form orbit of the piecewise-linear law.
TEST(Simulation, CustomLawOnAdaptivePathReproducesClosedFormOrbit) {
  const double ka = 10, kb = 8, fa = 0.3, fb = 0.6, l = 9.5;
  impact::CustomLaw custom{[=](double d) { return d < 0 ? -(fa + ka * d) : 0.0; },
                           [=](double d) { return d < 0 ? -(fb + kb * d) : 0.0; }, {0.0}, "custom_hysteresis"};
  const TappingModel linear = testing::attractive_model(l);
  const TappingModel callable(linear.cantilever, linear.drive, impact::ForceLaw(custom), l);
  const auto exact = shoot(linear, free_response_state(linear), 1);
  ShootingOptions o;
  o.simulation.relative_tolerance = 1e-12;
  o.simulation.absolute_tolerance = 1e-13;
  const auto generic = shoot(callable, exact.initial, 1, o);
  EXPECT_EQ(resolve_integrator(callable, Integrator::automatic), Integrator::adaptive);
  EXPECT_NEAR(generic.initial.position, exact.initial.position, 1e-8);
  EXPECT_NEAR(generic.initial.velocity, exact.initial.velocity, 1e-8);
  EXPECT_NEAR(generic.floquet_max, exact.floquet_max, 1e-5);  // monodromy: slopes by one-sided differences
}

// DMT (nonlinear, adaptive integrator): a periodic tapping orbit whose energy balance closes to the
// integrator's accuracy.
TEST(Simulation, DmtOrbitEnergyBalance) {
  // k = 40 N/m cantilever: forces in nN / 40 -> normalised units (nm ω_n²)
  const impact::DmtLaw dmt(1.0, 0.8, 10.0, 6.4e-20, 1.0e-19, 0.165);
  const TappingModel model(Cantilever(1.0, 100.0), Drive(0.2, 1.0), impact::ForceLaw(dmt).scaled(1.0 / 40.0), 15.0);
  const TransientOutcome t = settle(model, free_response_state(model));
  ASSERT_EQ(t.kind, ResponseKind::periodic);
  const auto m = analyse_orbit(model, *t.orbit);
  EXPECT_LT(m.min_gap, 0.165);  // reaches contact (gap below a0)
  EXPECT_GT(m.contact_dissipation, 0.0);
  EXPECT_NEAR(m.drive_work, m.energy_dissipated(), 1e-7 * m.drive_work);
}

}  // namespace
}  // namespace afmkit::tapping
