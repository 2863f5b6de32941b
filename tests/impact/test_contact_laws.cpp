// The built-in contact laws of contact_laws.hpp against independent computations: forces as −dU/dd of their
// potentials (finite differences of an independently written energy), hysteresis areas against quadrature,
// dissipation checks naming the parameter, and Kelvin–Voigt losses in an impact against the integrated ∫c ḋ² dt.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/impact.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"

using namespace afmkit;
using namespace afmkit::impact;

namespace {
// composite Simpson on [a, b] with n (even) panels
template <class F>
double simpson(F f, double a, double b, int n = 20000) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
  return s * h / 3.0;
}
// −dU/dd by a 4th-order central difference
template <class U>
double minus_derivative(U u, double d, double h = 1e-5) {
  return -(-u(d + 2 * h) + 8 * u(d + h) - 8 * u(d - h) + u(d - 2 * h)) / (12 * h);
}
}  // namespace

TEST(HertzLaw, ForceIsMinusDerivativeOfHertzEnergyAndAreaMatchesQuadrature) {
  const HertzLaw law(2.0, 1.5, 8.0);
  // U(δ) = (8/15) E* √R δ^{5/2}, δ = −d
  auto energy = [](double e, double d) { return d < 0 ? 8.0 / 15.0 * e * std::sqrt(8.0) * std::pow(-d, 2.5) : 0.0; };
  for (double d : {-2.0, -0.7, -0.01}) {
    EXPECT_NEAR(law.approach(d), minus_derivative([&](double x) { return energy(2.0, x); }, d), 1e-7);
    EXPECT_NEAR(law.departure(d), minus_derivative([&](double x) { return energy(1.5, x); }, d), 1e-7);
  }
  EXPECT_EQ(law.approach(0.5), 0.0);
  const double area = simpson([&](double d) { return law.approach(d) - law.departure(d); }, -1.3, 0.0);
  EXPECT_NEAR(law.hysteresis_area(-1.3, 2.0), area, 1e-10 * area);
  EXPECT_NO_THROW(law.require_dissipative());
  try {
    HertzLaw(1.0, 1.5, 8.0).require_dissipative();
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "departure_modulus");
  }
  EXPECT_THROW(HertzLaw(-1.0, 1.0, 1.0), InvalidParameter);
  EXPECT_THROW(HertzLaw(1.0, 1.0, std::nan("")), InvalidParameter);
}

TEST(LennardJonesLaw, ForceIsMinusDerivativeOfSpherePlanePotentialZeroAtA0AndC1AtTheCut) {
  const double r = 10.0, a_h = 6.4e-20, a0 = 0.3;
  const LennardJonesLaw law(r, a_h, a0);
  // sphere–plane 6–12: U(d) = −(A_H R/6)(1/d − a0⁶/(7 d⁷)), A_H in J → nN·nm: ×1e18
  auto energy = [&](double d) { return -(a_h * 1e18 * r / 6.0) * (1.0 / d - std::pow(a0, 6) / (7.0 * std::pow(d, 7))); };
  for (double d : {0.2, 0.3, 0.5, 2.0, 10.0}) EXPECT_NEAR(law.approach(d), minus_derivative(energy, d, 1e-6), 1e-5 * (1 + std::abs(law.approach(d))));
  EXPECT_NEAR(law.approach(a0), 0.0, 1e-12);
  EXPECT_EQ(law.departure(0.7), law.approach(0.7));
  const double cut = 0.5 * a0, h = 1e-9;
  EXPECT_NEAR(law.approach(cut - h), law.approach(cut + h), 1e-5 * std::abs(law.approach(cut)));
  const double slope_below = (law.approach(cut - h) - law.approach(cut - 2 * h)) / h;
  const double slope_above = (law.approach(cut + 2 * h) - law.approach(cut + h)) / h;
  EXPECT_NEAR(slope_below, slope_above, 1e-3 * std::abs(slope_above));
  EXPECT_TRUE(std::isfinite(law.approach(-1.0)));
  EXPECT_THROW(LennardJonesLaw(r, 0.0, a0), InvalidParameter);
}

TEST(AdhesionHysteresisLaw, PullOffIsJkrAndLossIsTheAreaBetweenTheBranches) {
  const double e = 1.0, r = 10.0, a_h = 6.4e-20, a0 = 0.165, gamma = 0.1;
  const AdhesionHysteresisLaw law(e, r, a_h, a0, gamma);
  EXPECT_NEAR(law.pull_off_force(), 1.5 * std::numbers::pi * gamma * r, 1e-12);
  const DmtLaw dmt(e, e, r, a_h, a_h, a0);
  for (double d : {-1.0, 0.0, 0.1, 0.165, 0.5, 3.0}) EXPECT_DOUBLE_EQ(law.approach(d), dmt.approach(d));
  // retract: DMT shifted by the adhesion difference in contact, van der Waals outside
  const double f_vdw = a_h * 1e18 * r / (6 * a0 * a0);
  EXPECT_NEAR(law.departure(-0.5), dmt.approach(-0.5) - (law.pull_off_force() - f_vdw), 1e-12);
  EXPECT_EQ(law.departure(0.5), dmt.approach(0.5));
  const double area = simpson([&](double d) { return law.approach(d) - law.departure(d); }, -0.8, a0 - 1e-13);
  EXPECT_NEAR(law.hysteresis_area(-0.8, 5.0), area, 1e-9 * area);
  EXPECT_NO_THROW(law.require_dissipative());
  try {
    AdhesionHysteresisLaw(e, r, a_h, a0, 0.01).require_dissipative();  // pull-off below the vdW adhesion
    FAIL();
  } catch (const InvalidParameter& ex) {
    EXPECT_EQ(ex.parameter(), "adhesion_energy");
  }
  EXPECT_NO_THROW(AdhesionHysteresisLaw(e, r, a_h, a0, 0.01, true).require_dissipative());
}

TEST(KelvinVoigtLaw, ImpactLosesExactlyTheViscousWork) {
  // DMT elastic part (conservative) + c(d) = 1e-9 η √(R(a0 − d)) nN·s/nm. Masses in kg, speeds in nm/s.
  const double eta = 100.0, r = 10.0, a0 = 0.165;
  const KelvinVoigtLaw kv(1.0, r, 0.0, a0, eta);
  EXPECT_EQ(kv.damping(0.2), 0.0);
  EXPECT_NEAR(kv.damping(-0.835), 1e-9 * eta * std::sqrt(r * 1.0), 1e-18);
  const ForceLaw law(std::make_shared<const KelvinVoigtLaw>(kv));
  ASSERT_TRUE(law.has_damping());
  const double m = 1e-11;  // kg
  ImpactOptions o;
  o.history_points = 200001;
  const ImpactProblem problem({m, 0.0, 0.0}, {m, 1.0, -2e7}, law, {});  // gap 1 nm, closing at 2e7 nm/s
  const ImpactResult res = simulate_impact(problem, o);
  ASSERT_EQ(res.outcome, ImpactOutcome::separated);
  EXPECT_LT(res.restitution, 1.0);
  // ∫ c(d) ḋ² dt over the history (trapezoid on the dense samples) = kinetic energy lost
  double work = 0.0;
  for (std::size_t i = 1; i < res.history.size(); ++i) {
    const auto& p = res.history[i - 1];
    const auto& q = res.history[i];
    const double fp = kv.damping(p.gap) * p.gap_rate * p.gap_rate, fq = kv.damping(q.gap) * q.gap_rate * q.gap_rate;
    work += 0.5 * (fp + fq) * (q.time - p.time);
  }
  EXPECT_NEAR(res.kinetic_energy_loss, work, 1e-5 * work);
  EXPECT_GT(work, 0.0);
}

// Closed-form slopes dH/dd (used by the variational equations) against a fourth-order central difference of the
// force itself, on both sides of every switching gap.
TEST(ContactLawSlopes, EqualTheDerivativeOfTheForceAwayFromSwitchingGaps) {
  const std::vector<ForceLaw> laws = {
      ForceLaw(DmtLaw(1.3, 0.9, 10.0, 6.4e-20, 8e-20, 0.165)),
      make_law<HertzLaw>(1.3, 0.9, 10.0),
      make_law<AdhesionHysteresisLaw>(1.0, 10.0, 6.4e-20, 0.165, 0.05),
      make_law<LennardJonesLaw>(10.0, 6.4e-20, 0.3),
  };
  for (const ForceLaw& law : laws) {
    ASSERT_TRUE(law.has_slopes()) << law.name();
    for (double d = -1.5; d <= 3.0; d += 0.0173) {
      const double h = 1e-4;
      bool near_switch = false;
      for (double g : law.switching_gaps()) near_switch |= std::abs(d - g) < 3 * h;
      if (near_switch) continue;
      auto diff = [&](auto&& f) { return (-f(d + 2 * h) + 8 * f(d + h) - 8 * f(d - h) + f(d - 2 * h)) / (12 * h); };
      const double da = diff([&](double x) { return law.approach(x); });
      const double db = diff([&](double x) { return law.departure(x); });
      EXPECT_NEAR(law.approach_slope(d), da, 1e-6 * std::max(1.0, std::abs(da))) << law.name() << " d = " << d;
      EXPECT_NEAR(law.departure_slope(d), db, 1e-6 * std::max(1.0, std::abs(db))) << law.name() << " d = " << d;
    }
  }
}
