// Folds dl/dq = 0 (ext. E6) located to 1e-10 in q: checked by a least-squares polynomial fit of l(q) around
// each fold (independent of the analytic slope used by the library) and by the change in the number of
// solutions across l_fold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "afmkit/tapping/harmonic_balance.hpp"

namespace afmkit::tapping {
namespace {

using impact::PiecewiseLinearLaw;

// Vertex of the cubic least-squares fit of l(q) on [q* − r, q* + r] (the root of its derivative nearest q*).
double fitted_extremum(const TappingModel& model, const HbFold& fold, double radius) {
  const int n = 81;
  Eigen::MatrixXd v(n, 4);
  Eigen::VectorXd y(n);
  for (int k = 0; k < n; ++k) {
    const double u = -1.0 + 2.0 * k / (n - 1);
    const auto p = harmonic_balance_at_q(model, fold.point.q + radius * u, fold.point.branch);
    EXPECT_TRUE(p.has_value());
    v.row(k) << 1.0, u, u * u, u * u * u;
    y[k] = p->separation - fold.point.separation;
  }
  const Eigen::Vector4d c = v.colPivHouseholderQr().solve(y);
  // derivative c1 + 2 c2 u + 3 c3 u² = 0, root nearest 0 (stable form)
  const double a = 3 * c[3], b = 2 * c[2], cc = c[1];
  double u;
  if (std::abs(a) < 1e-300) {
    u = -cc / b;
  } else {
    const double disc = std::sqrt(b * b - 4 * a * cc);
    const double qq = -0.5 * (b + std::copysign(disc, b));
    u = cc / qq;  // the small root
  }
  return fold.point.q + radius * u;
}

struct Case {
  double w;
  PiecewiseLinearLaw law;
};

TEST(Folds, LocatedTo1e10AndChangeTheNumberOfSolutions) {
  const Case cases[] = {{0.995, PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6)},
                        {0.99, PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.5, 1.0)},
                        {1.005, PiecewiseLinearLaw::linear_hysteresis(10, 6.4)},
                        {1.01, PiecewiseLinearLaw::repulsive_attractive(1000, 640, 0.3, 0.6)}};
  int checked = 0;
  double worst = 0;
  for (const Case& c : cases) {
    const TappingModel model(Cantilever(1.0, 100.0), Drive(0.2, c.w), c.law, 0.0);
    const HarmonicBalance hb(model);
    ASSERT_FALSE(hb.folds().empty()) << "w=" << c.w;
    for (const HbFold& fold : hb.folds()) {
      const double q = fold.point.q;
      if (q < -1e3) continue;  // far permanent-contact folds: l is flat there
      // Fit radius: well inside the smooth piece around q*, shrinking near grazing and q = -1.
      const double radius = std::min({1e-6, 0.01 * (1.0 - q), 0.01 * std::abs(q + 1.0)});
      const double q_fit = fitted_extremum(model, fold, radius);
      EXPECT_NEAR(q_fit, q, 1e-10) << "w=" << c.w << " fold q=" << q;
      worst = std::max(worst, std::abs(q_fit - q));
      // l(q*) is a local extremum of the kind reported.
      const double h = radius;
      const double l_left = harmonic_balance_at_q(model, q - h, fold.point.branch)->separation;
      const double l_right = harmonic_balance_at_q(model, q + h, fold.point.branch)->separation;
      if (fold.separation_maximum) {
        EXPECT_GE(fold.point.separation, std::max(l_left, l_right));
      } else {
        EXPECT_LE(fold.point.separation, std::min(l_left, l_right));
      }
      // Two solutions appear / disappear across l_fold.
      const double eps = 1e-7 * std::max(1.0, std::abs(fold.point.separation));
      const int below = static_cast<int>(hb.solutions(fold.point.separation - eps).size());
      const int above = static_cast<int>(hb.solutions(fold.point.separation + eps).size());
      EXPECT_EQ(below - above, fold.separation_maximum ? 2 : -2) << "w=" << c.w << " fold q=" << q;
      ++checked;
    }
  }
  EXPECT_GE(checked, 4);
  std::printf("[ folds ] %d folds: max |q_fit - q_fold| = %.2e\n", checked, worst);
}

TEST(Folds, MathMdExample) {
  // docs/theory-tapping.md#two-branch-solution: l_max = 14.7161 at q = 0.998443 (python dense grid; grid spacing ~1e-6
  // there).
  const TappingModel model(Cantilever(1.0, 100.0), Drive(0.2, 0.995), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), 0.0);
  const auto folds = harmonic_balance_folds(model);
  const auto it = std::find_if(folds.begin(), folds.end(), [](const HbFold& f) { return f.point.q > 0.9; });
  ASSERT_NE(it, folds.end());
  EXPECT_TRUE(it->separation_maximum);
  EXPECT_EQ(it->point.branch, HbBranch::Plus);
  EXPECT_NEAR(it->point.separation, 14.7161, 1e-4);
  EXPECT_NEAR(it->point.q, 0.998443, 3e-6);
  // docs/theory-tapping.md#hb-accuracy demo case: fold l_max = 10.1003 (B = 10.1247), free amplitude 8.9982.
  const TappingModel sweep(Cantilever(1.0, 100.0), Drive(0.2, 0.99), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.5, 1.0), 0.0);
  const HarmonicBalance hb(sweep);
  EXPECT_NEAR(hb.free_amplitude(), 8.9982, 1e-4);
  double l_max = -INFINITY, b_at = 0;
  for (const HbFold& f : hb.folds())
    if (f.point.q > 0.9 && f.separation_maximum && f.point.separation > l_max) {
      l_max = f.point.separation;
      b_at = f.point.amplitude;
    }
  EXPECT_NEAR(l_max, 10.1003, 1e-4);
  EXPECT_NEAR(b_at, 10.1247, 1e-3);
}

TEST(Folds, NoneForRepulsiveBelowResonance) {
  // docs/theory-tapping.md#harmonic-balance: l(q) strictly increasing for ω ≤ ω_n in the repulsive model.
  for (double w : {0.99, 1.0})
    for (double ka : {1.0, 10.0, 1000.0}) {
      const TappingModel model(Cantilever(1.0, 100.0), Drive(0.2, w), PiecewiseLinearLaw::linear_hysteresis(ka, 0.64 * ka), 0.0);
      EXPECT_TRUE(harmonic_balance_folds(model).empty()) << "w=" << w << " K_a=" << ka;
    }
}

}  // namespace
}  // namespace afmkit::tapping
