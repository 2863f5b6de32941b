// Every built-in force law in the tapping model: the library's adaptive integrator with event location against
// an independent adaptive RK4 with bisection event location (reference_hybrid.hpp), and the energy balance of
// converged orbits (drive work = viscous + contact dissipation, exact for a periodic orbit).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "afmkit/impact/law_registry.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"
#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/simulation.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"
#include "reference_hybrid.hpp"

using namespace afmkit;

namespace {

struct Case {
  std::string law;
  impact::LawArguments args;
  double separation;  // nm
};

impact::LawArguments table_args() {
  impact::LawArguments a;
  a.force_curve = std::string(AFMKIT_SOURCE_DIR) + "/examples/force_curves/dmt_adhesion.csv";
  // the table law's default, contact-aware branch selection (docs/force-laws.md#hysteresis): the reference
  // integrator models the memory of contact independently
  return a;
}

std::vector<Case> cases() {
  auto with = [](std::map<std::string, double> v) {
    impact::LawArguments a;
    a.values = std::move(v);
    return a;
  };
  return {
      {"hertz", with({{"effective_modulus", 1.0}, {"departure_modulus", 0.7}}), 8.0},
      {"dmt", with({{"departure_hamaker", 1.2e-19}, {"departure_modulus", 0.8}}), 8.0},
      {"jkr", with({}), 8.0},
      {"lennard_jones", with({}), 8.5},
      {"kelvin_voigt", with({{"viscosity", 200.0}}), 8.0},
      {"attractive", with({{"approach_stiffness", 400.0}, {"departure_stiffness", 320.0}, {"approach_adhesion", 1.0},
                           {"departure_adhesion", 3.0}}),
       8.0},
      {"table", table_args(), 8.0},
  };
}

// k = 40 N/m, f0 = 300 kHz, Q = 400, free amplitude 10 nm, drive at resonance
tapping::TappingModel model_for(const Case& c) {
  const tapping::PhysicalCantilever pc(40.0, 300.0, 400.0, 10.0, 1.0);
  const impact::ForceLaw law = impact::LawRegistry::builtin().build(c.law, c.args);
  return {pc.cantilever(), pc.drive(), pc.normalised_law(law), c.separation};
}

}  // namespace

TEST(LawFidelity, AdaptiveSimulationMatchesIndependentReferenceForEveryLaw) {
  for (const auto& c : cases()) {
    SCOPED_TRACE(c.law);
    const auto model = model_for(c);
    const tapping::TipState start = tapping::free_response_state(model);
    const double t_end = 3.0 * model.period();
    tapping::SimulationOptions o;
    o.integrator = tapping::Integrator::adaptive;
    o.relative_tolerance = 1e-12;
    o.absolute_tolerance = 1e-13;
    const auto lib = tapping::simulate(model, 0.0, start, t_end, o);
    EXPECT_GE(lib.stats.impacts, 2);  // the tip does reach the sample
    const afmkit_test::ReferenceHybrid ref(model);
    const auto r = ref.run(0.0, {start.position, start.velocity}, t_end, 1e-12);
    const double scale = model.free_amplitude();
    EXPECT_NEAR(lib.state.position, r.x, 2e-8 * scale);
    EXPECT_NEAR(lib.state.velocity, r.v, 2e-8 * scale);
  }
}

TEST(LawFidelity, EnergyBalanceOfConvergedOrbitsForEveryLaw) {
  for (auto c : cases()) {
    SCOPED_TRACE(c.law);
    // with the contact-aware rule the tip at 8 nm grazes the table's contact gap (lowest gap ≈ 0.2 nm against
    // d_c = 0.166 nm): it touches on some cycles only, a motion with no periodic orbit to balance; the seed's
    // velocity-sign rule has one (the contact-aware energy balance: test_contact_hysteresis.cpp)
    if (c.law == "table") c.args.hysteresis = "velocity";
    const auto model = model_for(c);
    tapping::ShootingOptions so;
    so.tolerance = 1e-14;
    so.simulation.relative_tolerance = 1e-13;
    so.simulation.absolute_tolerance = 1e-14;
    auto orbit = tapping::try_shoot(model, tapping::free_response_state(model), 1, so);
    if (!orbit) {  // settle first
      const auto settled = tapping::simulate(model, 0.0, tapping::free_response_state(model), 2000 * model.period());
      orbit = tapping::try_shoot(model, settled.state, 1, so);
    }
    ASSERT_TRUE(orbit.has_value());
    {
      tapping::SimulationOptions o;
      o.relative_tolerance = 1e-12;
      o.absolute_tolerance = 1e-13;
      o.relative_tolerance = 1e-13;
      o.absolute_tolerance = 1e-14;
      const auto m = tapping::analyse_orbit(model, *orbit, o);
      EXPECT_LT(m.min_gap, 0.2);  // touches the sample (gap about a0 or less)
      std::printf("%s: B = %.6f nm, min gap %.4f nm, W = %.9g, residual %.3g\n", c.law.c_str(), m.amplitude, m.min_gap,
                  m.drive_work, (m.drive_work - m.viscous_dissipation - m.contact_dissipation) / m.drive_work);
      // per drive period, per unit mass: W = ∫Γcos ωt ẋ dt = ∫2ξω_n ẋ² dt + ∫h ẋ dt
      EXPECT_NEAR(m.drive_work, m.viscous_dissipation + m.contact_dissipation, 1e-9 * std::abs(m.drive_work));
      if (c.law == "lennard_jones") {
        EXPECT_NEAR(m.contact_dissipation, 0.0, 1e-9 * std::abs(m.drive_work));
      }
      else EXPECT_GT(m.contact_dissipation, 0.0);
    }
  }
}

TEST(LawFidelity, TableSampledFromDmtAt200PointsReproducesItsSweep) {
  // the DMT + vdW law (with hysteresis) sampled at 200 gaps as a measured curve: the contact edge a0 is a
  // sample, spacing quadratic in the penetration inside (F ~ δ^{3/2}) and geometric in d − a0 outside (F ~ 1/d²)
  const impact::DmtLaw dmt(1.0, 0.8, 10.0, 6.4e-20, 1.0e-19, 0.165);
  impact::ForceCurve curve;
  curve.origin = "sampled dmt";
  std::vector<double> gaps;
  for (int k = 99; k >= 0; --k) gaps.push_back(0.165 - 3.0 * (k / 99.0) * (k / 99.0));  // −2.835 … a0
  for (int k = 0; k < 100; ++k) gaps.push_back(0.165 + 1e-3 * std::pow(3e4, k / 99.0));  // … 30.2 nm
  for (double d : gaps) {
    curve.approach_gap.push_back(d);
    curve.approach_force.push_back(dmt.approach(d));
  }
  curve.retract_gap = curve.approach_gap;
  for (double d : curve.retract_gap) curve.retract_force.push_back(dmt.departure(d));
  const tapping::PhysicalCantilever pc(40.0, 300.0, 400.0, 10.0, 1.0);
  const auto analytic = tapping::TappingModel(pc.cantilever(), pc.drive(), pc.normalised_law(dmt), 9.0);
  const auto table = tapping::TappingModel(pc.cantilever(), pc.drive(),
                                           pc.normalised_law(impact::make_law<impact::TableLaw>(curve, false, impact::Hysteresis::velocity)), 9.0);
  const auto a = tapping::sweep_instrument(analytic, 6.0, 9.5, 8, {});
  const auto t = tapping::sweep_instrument(table, 6.0, 9.5, 8, {});
  ASSERT_EQ(a.approach.size(), t.approach.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.approach.size(); ++i)
    worst = std::max(worst, std::abs(t.approach[i].metrics.amplitude / a.approach[i].metrics.amplitude - 1.0));
  std::printf("table vs analytic DMT sweep: max relative difference of B %.3g\n", worst);
  for (std::size_t i = 0; i < a.approach.size(); ++i) {
    SCOPED_TRACE(a.approach[i].separation);
    EXPECT_NEAR(t.approach[i].metrics.amplitude, a.approach[i].metrics.amplitude, 1e-4 * a.approach[i].metrics.amplitude);
  }
  for (std::size_t i = 0; i < a.retract.size(); ++i)
    EXPECT_NEAR(t.retract[i].metrics.amplitude, a.retract[i].metrics.amplitude, 1e-4 * a.retract[i].metrics.amplitude);
}
