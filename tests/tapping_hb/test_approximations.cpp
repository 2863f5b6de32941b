// Large-stiffness approximations (seed-1 eqs. 20–25) approached as K_a grows, and the limit E8 by evaluation
// at very negative q.
#include <gtest/gtest.h>

#include <cmath>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/hb_approximations.hpp"

namespace afmkit::tapping {
namespace {

using impact::PiecewiseLinearLaw;

TappingModel resonant(double ka, double l, double w = 1.0) {
  // Q = 100, Γ|L(iω_n)| = 20 (the Figs. 3–4 values of docs/theory-tapping.md#large-stiffness), e = 0.8.
  return TappingModel(Cantilever(1.0, 100.0), Drive(0.2, w), PiecewiseLinearLaw::linear_hysteresis(ka, 0.64 * ka), l);
}

HbPoint contact_solution(const TappingModel& m) {
  const auto s = harmonic_balance_solutions(m);
  EXPECT_EQ(s.size(), 1u);
  return s.front();
}

TEST(Approximations, Eq20And22And25ApproachedAsStiffnessGrows) {
  for (double l : {15.0, 5.0}) {
    double previous20 = INFINITY, previous25 = INFINITY;
    for (double ka : {10.0, 100.0, 1e3, 1e4, 1e5, 1e6}) {
      const TappingModel m = resonant(ka, l);
      const HbPoint p = contact_solution(m);
      const double err20 = std::abs(impulsive_separation(p.amplitude, p.offset) - l);
      const double err25 = std::abs(impulsive_separation_from_phase(m, p.phase) - p.amplitude);
      EXPECT_LT(err20, previous20) << "K_a=" << ka;
      EXPECT_LT(err25, previous25) << "K_a=" << ka;
      previous20 = err20;
      previous25 = err25;
      // (21): 0 ≤ A ≤ Γ L(0); (22): B ≈ l up to A_max.
      EXPECT_GE(p.offset, 0.0);
      EXPECT_LE(p.offset, impulsive_offset_bound(m));
      EXPECT_LE(std::abs(p.amplitude - impulsive_amplitude(m)), impulsive_offset_bound(m) + err20);
      if (ka == 1e6) {
        EXPECT_LT(err20, 3e-4);
        EXPECT_LT(err25, 1e-2);  // (25) → B at rate ~K_a^(-1/3)
        // inverse of (25)
        EXPECT_NEAR(impulsive_phase(m.with_separation(p.amplitude)), p.phase, 2e-3);
      }
    }
  }
}

TEST(Approximations, OffsetBound21OnContactRangeBelowResonance) {
  for (double w : {0.99, 1.0})
    for (double ka : {1.0, 10.0, 1000.0}) {
      const TappingModel m = resonant(ka, 0.0, w);
      for (int k = 1; k < 2000; ++k) {
        const double q = -1.0 + 2.0 * k / 2000.0;
        const auto p = harmonic_balance_at_q(m, q, HbBranch::Plus);
        ASSERT_TRUE(p.has_value());
        EXPECT_GE(p->offset, 0.0);
        EXPECT_LE(p->offset, impulsive_offset_bound(m)) << "w=" << w << " K_a=" << ka << " q=" << q;
      }
    }
}

TEST(Approximations, Eq23And24AreIdentitiesOfEq18) {
  for (double w : {0.99, 1.0, 1.01})
    for (double q : {-0.9, -0.3, 0.2, 0.8, 0.999}) {
      const TappingModel m = resonant(10.0, 0.0, w);
      const auto p = harmonic_balance_at_q(m, q, HbBranch::Plus);
      ASSERT_TRUE(p.has_value());
      EXPECT_NEAR(repulsive_phase_sine(m, q), std::sin(p->phase), 1e-14);
      EXPECT_NEAR(repulsive_separation_from_phase(m, q), p->separation, 1e-12 * std::max(1.0, std::abs(p->separation)));
    }
  const TappingModel attractive(Cantilever(1.0, 100.0), Drive(0.2, 1.0), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), 0.0);
  EXPECT_THROW(repulsive_phase_sine(attractive, 0.5), InvalidParameter);
  EXPECT_THROW(repulsive_separation_from_phase(resonant(10, 0), 1.5), InvalidParameter);
  EXPECT_THROW(impulsive_phase(resonant(10, 25.0)), InvalidParameter);
}

TEST(Approximations, LimitE8ByEvaluationAtVeryNegativeQ) {
  struct Case {
    PiecewiseLinearLaw law;
    double w;
  };
  const Case cases[] = {{PiecewiseLinearLaw::linear_hysteresis(1.0, 0.8), 1.0},
                        {PiecewiseLinearLaw::linear_hysteresis(10.0, 8.0), 1.0},
                        {PiecewiseLinearLaw::linear_hysteresis(1000.0, 800.0), 0.99},
                        {PiecewiseLinearLaw::repulsive_attractive(10.0, 8.0, 0.1, 0.2), 1.0},
                        {PiecewiseLinearLaw::repulsive_attractive(8.0, 10.0, 0.1, 0.2), 1.003}};  // K_a < K_b
  for (const Case& c : cases) {
    const TappingModel m(Cantilever(1.0, 100.0), Drive(0.2, c.w), c.law, 0.0);
    const auto limit = minimum_separation_limit(m);
    ASSERT_TRUE(limit.has_value());
    const auto far = harmonic_balance_at_q(m, -1e8, HbBranch::Plus);
    ASSERT_TRUE(far.has_value());
    EXPECT_NEAR(far->separation, *limit, 1e-6 * std::max(1.0, std::abs(*limit)));  // l − l_∞ = O(1/q)
  }
  // docs/theory-tapping.md#minimum-separation values (printed to 4 decimals): −2.9845 (K_a = 1), −1.5708 (K_a = 10).
  auto e08 = [](double ka) {
    return TappingModel(Cantilever(1.0, 100.0), Drive(0.2, 1.0), PiecewiseLinearLaw::linear_hysteresis(ka, 0.8 * ka), 0.0);
  };
  EXPECT_NEAR(*minimum_separation_limit(e08(1.0)), -2.9845, 1e-4);
  EXPECT_NEAR(*minimum_separation_limit(e08(10.0)), -1.5708, 1e-4);
  // The "+" branch does not reach q → −∞ when 2Δ_F/π ≥ Γ.
  const TappingModel sticky(Cantilever(1.0, 100.0), Drive(0.2, 1.0), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.0, 1.0), 0.0);
  EXPECT_FALSE(minimum_separation_limit(sticky).has_value());
  EXPECT_FALSE(harmonic_balance_at_q(sticky, -1e9, HbBranch::Plus).has_value());
  // K_a = K_b: l → −∞.
  const TappingModel elastic(Cantilever(1.0, 100.0), Drive(0.2, 1.0), PiecewiseLinearLaw::linear_repulsive(10.0), 0.0);
  EXPECT_EQ(*minimum_separation_limit(elastic), -INFINITY);
  EXPECT_LT(harmonic_balance_at_q(elastic, -1e9, HbBranch::Plus)->separation, -1e6);
}

}  // namespace
}  // namespace afmkit::tapping
