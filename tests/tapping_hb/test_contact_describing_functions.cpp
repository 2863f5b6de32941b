// Describing functions of a contact-aware table law (docs/force-laws.md#hysteresis) over the cycle
// d = g + B cos θ: a cycle that does not reach the contact gap is free (H_a on both halves: the describing
// functions of the approach-only, conservative law, Im N1 = 0); a cycle that reaches it is the velocity-sign law's.
#include <cmath>

#include <gtest/gtest.h>

#include "../tapping_sim/contact_curve.hpp"
#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/tapping/numerical_describing_functions.hpp"

using namespace afmkit;
using impact::Hysteresis;

namespace {
impact::ForceLaw table(const impact::ForceCurve& c, Hysteresis h) {
  return impact::make_law<impact::TableLaw>(c, false, h);
}
}  // namespace

TEST(ContactDescribingFunctions, AFreeCycleIsConservativeAndATouchingOneIsTheVelocityLaws) {
  const tapping::DescribingFunctionQuadrature aware(table(afmkit_test::neck_curve(), Hysteresis::contact), 1.0);
  const tapping::DescribingFunctionQuadrature seed(table(afmkit_test::neck_curve(), Hysteresis::velocity), 1.0);
  const tapping::DescribingFunctionQuadrature conservative(
      table(afmkit_test::approach_only_curve(), Hysteresis::velocity), 1.0);
  // free: lowest gap 5 nm, inside the neck range (5 … 14 nm) but above the contact gap
  {
    const auto a = aware.at_gap(12.0, 7.0), s = seed.at_gap(12.0, 7.0), c = conservative.at_gap(12.0, 7.0);
    EXPECT_EQ(a.first_harmonic.imag(), 0.0);  // no dissipation through the law
    EXPECT_GT(s.first_harmonic.imag(), 0.0);  // the seed's rule: the neck dissipates at every cycle
    // (the contact-aware law has two more switching gaps: other quadrature pieces, same integrand)
    EXPECT_NEAR(a.first_harmonic.real(), c.first_harmonic.real(), 1e-9 * std::abs(c.first_harmonic.real()));
    EXPECT_NEAR(a.mean, c.mean, 1e-9 * std::abs(c.mean));
  }
  // touching: lowest gap −1 nm; H_a = H_b above the release gap, so contact-aware = velocity-sign
  {
    const auto a = aware.at_gap(6.0, 7.0), s = seed.at_gap(6.0, 7.0);
    EXPECT_GT(a.first_harmonic.imag(), 0.0);
    EXPECT_NEAR(a.first_harmonic.imag(), s.first_harmonic.imag(), 1e-8 * s.first_harmonic.imag());  // (quadrature tolerance)
    EXPECT_NEAR(a.first_harmonic.real(), s.first_harmonic.real(), 1e-9 * std::abs(s.first_harmonic.real()));
    EXPECT_NEAR(a.mean, s.mean, 1e-9 * std::abs(s.mean));
  }
}
