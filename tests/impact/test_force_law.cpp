// Force laws (seed-1 eqs. 4, 10, 11, 26; DMT): branch values, continuity, units, custom laws, bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/force_law.hpp"

using afmkit::InvalidParameter;
using namespace afmkit::impact;

TEST(PiecewiseLinearLaw, BranchesFollowTheTappingSignConvention) {
  const PiecewiseLinearLaw p(10.0, 8.0, 0.3, 0.5);
  // H_a(d) = −(F_a + K_a d) for d < 0, 0 outside contact
  EXPECT_DOUBLE_EQ(p.approach(-2.0), -(0.3 + 10.0 * -2.0));
  EXPECT_DOUBLE_EQ(p.departure(-2.0), -(0.5 + 8.0 * -2.0));
  EXPECT_EQ(p.approach(0.0), 0.0);
  EXPECT_EQ(p.departure(1.0), 0.0);
  // adhesion pulls at the contact edge (H < 0 attractive)
  EXPECT_LT(p.departure(-1e-12), 0.0);
}

TEST(ForceLaw, Eq4SelectsBranchBySignOfGapRate) {
  const ForceLaw law(PiecewiseLinearLaw::linear_hysteresis(10.0, 4.0));
  EXPECT_DOUBLE_EQ(law.force(-1.0, -1.0), 10.0);  // approaching: H_a
  EXPECT_DOUBLE_EQ(law.force(-1.0, +1.0), 4.0);   // departing: H_b
  EXPECT_DOUBLE_EQ(law.force(-1.0, 0.0), 7.0);    // ḋ = 0: mean
  EXPECT_EQ(law.name(), "hysteresis");
  EXPECT_EQ(law.switching_gaps(), std::vector<double>{0.0});
}

TEST(ForceLaw, ScaledPiecewiseLinearCoefficientsAreScaled) {
  const ForceLaw law = ForceLaw(PiecewiseLinearLaw(10.0, 8.0, 0.3, 0.5)).scaled(2.5);
  ASSERT_NE(law.piecewise_linear(), nullptr);
  EXPECT_DOUBLE_EQ(law.piecewise_linear()->approach_stiffness, 25.0);
  EXPECT_DOUBLE_EQ(law.piecewise_linear()->departure_adhesion, 1.25);
  EXPECT_DOUBLE_EQ(law.approach(-1.0), 2.5 * (10.0 - 0.3));
  EXPECT_THROW(law.scaled(0.0), InvalidParameter);
}

TEST(PiecewiseLinearLaw, RejectsBadCoefficientsNamingThem) {
  try {
    PiecewiseLinearLaw(-1.0, 1.0);
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "approach_stiffness");
  }
  try {
    PiecewiseLinearLaw(1.0, 1.0, 0.5, 0.2);  // F_b < F_a
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "departure_adhesion");
  }
  EXPECT_THROW(PiecewiseLinearLaw(1.0, std::nan("")), InvalidParameter);
  EXPECT_THROW(PiecewiseLinearLaw::departure_stiffness_for_restitution(1.0, 1.5), InvalidParameter);
}

TEST(DmtLaw, ContinuousAtTheIntermolecularDistance) {
  const DmtLaw dmt(1.2, 0.7, 10.0, 6.4e-20, 9e-20, 0.165);
  const double a0 = 0.165;
  // jump over [a0 − ε, a0 + ε] shrinks like ε (van der Waals slope A R/(3 a0³) ≈ 50 nN/nm here), so the
  // branches join continuously; a discontinuity would leave an O(1) jump.
  for (double eps : {1e-4, 1e-7, 1e-10}) {
    EXPECT_LT(std::abs(dmt.approach(a0 - eps) - dmt.approach(a0 + eps)), 100.0 * eps + 1e-13);
    EXPECT_LT(std::abs(dmt.departure(a0 - eps) - dmt.departure(a0 + eps)), 100.0 * eps + 1e-13);
  }
  // pull-off force −A_H R/(6 a0²) at d = a0 (J·nm/nm² = 1e18 nN)
  EXPECT_NEAR(dmt.approach(a0), -6.4e-20 * 1e18 * 10.0 / (6.0 * a0 * a0), 1e-12);
}

TEST(DmtLaw, HertzTermInSiUnits) {
  // Independent SI evaluation: F = 4/3 E* √R δ^{3/2} − A R/(6 a0²), E* = 2 GPa, R = 20 nm, δ = 1.5 nm.
  const double e_si = 2e9, r_si = 20e-9, delta_si = 1.5e-9, a0_si = 0.2e-9, hamaker = 5e-20;
  const double f_si = 4.0 / 3.0 * e_si * std::sqrt(r_si) * std::pow(delta_si, 1.5) - hamaker * r_si / (6 * a0_si * a0_si);
  const DmtLaw dmt(2.0, 2.0, 20.0, hamaker, hamaker, 0.2);
  EXPECT_NEAR(dmt.approach(0.2 - 1.5), f_si * 1e9, 1e-12 * std::abs(f_si * 1e9));
  // van der Waals branch at d = 3 nm
  EXPECT_NEAR(dmt.approach(3.0), -hamaker * r_si / (6 * 9e-18) * 1e9, 1e-14);
}

TEST(DmtLaw, DissipativeBranchesOrdered) {
  // E*_b ≤ E*_a and A_H,b ≥ A_H,a give H_a ≥ H_b everywhere (U_a ≥ U_b, seed-1 §II)
  const ForceLaw law(DmtLaw(1.0, 0.6, 10.0, 6e-20, 1e-19, 0.165));
  for (double d = -3.0; d < 5.0; d += 0.01) EXPECT_GE(law.approach(d), law.departure(d)) << d;
  EXPECT_EQ(law.name(), "dmt");
  EXPECT_EQ(law.piecewise_linear(), nullptr);
  EXPECT_EQ(law.switching_gaps(), std::vector<double>{0.165});
}

TEST(DmtLaw, RejectsBadParameters) {
  try {
    DmtLaw(1.0, 1.0, -10.0, 6e-20, 6e-20, 0.165);
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "tip_radius");
  }
  EXPECT_THROW(DmtLaw(1.0, 1.0, 10.0, 6e-20, 6e-20, 0.0), InvalidParameter);
  EXPECT_THROW(DmtLaw(std::nan(""), 1.0, 10.0, 6e-20, 6e-20, 0.1), InvalidParameter);
}

TEST(CustomLaw, LambdasAreUsedAndSwitchingGapsSorted) {
  CustomLaw c{[](double d) { return d < 1 ? 3.0 * (1 - d) : 0.0; }, [](double d) { return d < 1 ? 1.0 - d : 0.0; },
              {1.0, -2.0}, "my_law"};
  const ForceLaw law(c);
  EXPECT_DOUBLE_EQ(law.approach(0.0), 3.0);
  EXPECT_DOUBLE_EQ(law.departure(0.0), 1.0);
  EXPECT_DOUBLE_EQ(law.scaled(2.0).approach(0.0), 6.0);
  EXPECT_EQ(law.switching_gaps(), (std::vector<double>{-2.0, 1.0}));
  EXPECT_EQ(law.name(), "my_law");
  EXPECT_THROW(ForceLaw(CustomLaw{{}, [](double) { return 0.0; }, {}}), InvalidParameter);
}
