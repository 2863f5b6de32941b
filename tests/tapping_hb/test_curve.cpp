// The sampled parametric curve agrees point by point with harmonic_balance_at_q; option validation.
#include <gtest/gtest.h>

#include <cmath>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"

namespace afmkit::tapping {
namespace {

using impact::PiecewiseLinearLaw;

const TappingModel model(Cantilever(1.0, 100.0), Drive(0.2, 0.995), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), 0.0);

TEST(Curve, UniformSamplesMatchPointEvaluation) {
  HbCurveOptions o;
  o.q_min = -2.0;
  o.q_max = 1.5;
  o.points = 351;
  o.spacing = HbCurveSpacing::Uniform;
  const auto curve = harmonic_balance_curve(model, o);
  int plus_or_free = 0;
  double last_q = -INFINITY;
  bool in_minus = false;
  for (const HbPoint& p : curve) {
    if (p.branch == HbBranch::Minus) {
      if (!in_minus) last_q = -INFINITY;
      in_minus = true;
    } else {
      EXPECT_FALSE(in_minus) << "Plus/Free points come first";
      ++plus_or_free;
    }
    EXPECT_GT(p.q, last_q);
    last_q = p.q;
    const auto ref = harmonic_balance_at_q(model, p.q, p.branch);
    ASSERT_TRUE(ref.has_value());
    EXPECT_DOUBLE_EQ(ref->separation, p.separation);
    EXPECT_DOUBLE_EQ(ref->amplitude, p.amplitude);
    EXPECT_DOUBLE_EQ(ref->phase, p.phase);
  }
  // Count of Plus/Free points = samples where the "+" root exists (all of them here).
  int expected = 0;
  for (int k = 0; k < 351; ++k)
    if (harmonic_balance_at_q(model, -2.0 + 3.5 * k / 350.0, HbBranch::Plus)) ++expected;
  EXPECT_EQ(plus_or_free, expected);
  EXPECT_DOUBLE_EQ(curve.front().q, -2.0);
}

TEST(Curve, RefinedSamplesReachGrazing) {
  HbCurveOptions o;
  o.q_min = -1.0;
  o.q_max = 1.2;
  o.points = 1000;
  o.min_gap = 1e-9;
  o.include_minus = false;
  std::vector<HbPoint> curve;
  harmonic_balance_curve(model, o, curve);
  EXPECT_EQ(curve.size(), 1000u);
  double smallest_gap = INFINITY;
  for (std::size_t k = 0; k < curve.size(); ++k) {
    if (k > 0) {
      EXPECT_GT(curve[k].q, curve[k - 1].q);  // no repeated samples
    }
    if (curve[k].q < 1.0) smallest_gap = std::min(smallest_gap, 1.0 - curve[k].q);
  }
  EXPECT_NEAR(smallest_gap, 1e-9, 1e-12);
  EXPECT_EQ(curve.back().branch, HbBranch::Free);
}

TEST(Curve, RefinedSamplesBelowGrazingAreDistinct) {
  HbCurveOptions o;
  o.q_min = -0.5;
  o.q_max = 0.9;  // 1 − q_max > min_gap: the log samples stop short of q_max
  o.points = 101;
  o.include_minus = false;
  const auto curve = harmonic_balance_curve(model, o);
  ASSERT_EQ(curve.size(), 101u);
  EXPECT_DOUBLE_EQ(curve.front().q, -0.5);
  EXPECT_DOUBLE_EQ(curve.back().q, 0.9);
  for (std::size_t k = 1; k < curve.size(); ++k) EXPECT_GT(curve[k].q, curve[k - 1].q);
}

TEST(Curve, BadOptions) {
  HbCurveOptions o;
  o.q_min = 1.0;
  o.q_max = 1.0;
  EXPECT_THROW(harmonic_balance_curve(model, o), InvalidParameter);
  o.q_max = 2.0;
  o.points = 1;
  EXPECT_THROW(harmonic_balance_curve(model, o), InvalidParameter);
  o.points = 10;
  o.q_min = std::nan("");
  EXPECT_THROW(harmonic_balance_curve(model, o), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
