// All solutions at fixed separation (docs/theory-tapping.md#two-branch-solution) against multi-start Newton on (17)
// with quadrature DFs, and against an independent dense scan of l(q).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "reference.hpp"

namespace afmkit::tapping {
namespace {

using impact::PiecewiseLinearLaw;
using std::numbers::pi;

// docs/theory-tapping.md#two-branch-solution example: Q = 100, ω_n = 1, Γ = 0.2, K_a = 10, K_b = 8, F_a = 0.3,
// F_b = 0.6, ω = 0.995.
TappingModel example(double l) {
  return TappingModel(Cantilever(1.0, 100.0), Drive(0.2, 0.995), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), l);
}

TEST(Solutions, MultiStartNewtonFindsExactlyTheClosedFormSolutions) {
  const HarmonicBalance hb(example(0.0));
  double worst = 0;
  for (double l : {14.5, 14.0, 10.0, 0.15}) {
    const TappingModel model = example(l);
    const std::vector<HbPoint> closed = hb.solutions(l);
    // Starts: a coarse grid in (A, B, φ) plus points near each closed-form solution.
    std::vector<std::array<double, 3>> starts;
    for (double a : {-0.1, 0.0, 0.1})
      for (double b : {0.02, 0.2, 2.0, 8.0, 14.0, 16.0})
        for (double p : {0.3, 1.2}) starts.push_back({a, b, p});
    for (const HbPoint& c : closed) starts.push_back({c.offset, c.amplitude * 1.001, c.phase + 1e-3});
    std::vector<test::NewtonSolution> found;
    for (const auto& s : starts) {
      const auto sol = test::newton_solve(model, s[0], s[1], s[2]);
      if (!sol) continue;
      const bool seen = std::any_of(found.begin(), found.end(), [&](const test::NewtonSolution& f) {
        return std::abs(f.amplitude - sol->amplitude) < 1e-7 * std::max(1.0, sol->amplitude) &&
               std::abs(f.offset - sol->offset) < 1e-8;
      });
      if (!seen) found.push_back(*sol);
    }
    // Every Newton solution lies on a closed-form solution and vice versa.
    for (const auto& f : found) {
      double best = INFINITY;
      for (const HbPoint& c : closed)
        best = std::min(best, std::abs(f.amplitude - c.amplitude) + std::abs(f.offset - c.offset) +
                                  std::abs(std::remainder(f.phase - c.phase, 2 * pi)));
      EXPECT_LT(best, 1e-9) << "Newton solution B=" << f.amplitude << " at l=" << l << " not in the closed form set";
      worst = std::max(worst, best);
    }
    EXPECT_EQ(found.size(), closed.size()) << "l=" << l;
    std::printf("[ solutions ] l=%-5g closed form %zu, multi-start Newton %zu\n", l, closed.size(), found.size());
  }
  std::printf("[ solutions ] max distance Newton -> closed form: %.2e\n", worst);
}

TEST(Solutions, ExampleFromMathMd) {
  const auto at = harmonic_balance_solutions(example(14.5));
  ASSERT_EQ(at.size(), 3u);  // free + two contact solutions (docs/theory-tapping.md#two-branch-solution)
  EXPECT_NEAR(at[0].amplitude, 14.195357, 1e-6);
  EXPECT_EQ(at[0].branch, HbBranch::Free);
  EXPECT_NEAR(at[1].amplitude, 14.500637, 1e-6);
  EXPECT_NEAR(at[2].amplitude, 14.547813, 1e-6);
  EXPECT_NEAR(at[2].q, 0.996454, 1e-6);
  const auto low = harmonic_balance_solutions(example(0.15));
  ASSERT_EQ(low.size(), 3u);  // two on "+", one on "−"
  EXPECT_EQ(std::count_if(low.begin(), low.end(), [](const HbPoint& p) { return p.branch == HbBranch::Minus; }), 1);
}

TEST(Solutions, AreOnTheirBranchSortedAndConsistent) {
  for (double w : {0.99, 1.0, 1.005}) {
    const TappingModel base(Cantilever(1.0, 100.0), Drive(0.2, w), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.5, 1.0), 0.0);
    const HarmonicBalance hb(base);
    for (double l : {-1.0, 0.1, 2.0, 8.0, 9.5, 10.05, 12.0, 25.0}) {
      const auto sols = hb.solutions(l);
      for (std::size_t k = 0; k < sols.size(); ++k) {
        const HbPoint& p = sols[k];
        if (k > 0) {
          EXPECT_LE(sols[k - 1].amplitude, p.amplitude);
        }
        EXPECT_NEAR(p.separation, l, 1e-12 * std::max(1.0, std::abs(l)));
        EXPECT_NEAR((p.offset + l) / p.amplitude, p.q, 1e-11 * std::max(1.0, std::abs(p.q)));
        const auto again = hb.at_q(p.q, p.branch);
        ASSERT_TRUE(again.has_value());
        EXPECT_NEAR(again->amplitude, p.amplitude, 1e-6 * p.amplitude);  // q is rounded near grazing
      }
      const auto direct = harmonic_balance_solutions(base.with_separation(l));
      EXPECT_EQ(direct.size(), sols.size());
    }
  }
}

// Count sign changes of l_σ(q) − l on a fine grid independent of the library's scan grid.
int dense_count(const HarmonicBalance& hb, double l) {
  int count = l >= hb.free_amplitude() ? 1 : 0;
  for (HbBranch branch : {HbBranch::Plus, HbBranch::Minus}) {
    std::vector<double> qs;
    for (int k = 20000; k > 0; --k) qs.push_back(-30.0 * std::pow(10.0, 11.0 * k / 20000.0));  // to −3e12
    for (int k = 0; k <= 20000; ++k) qs.push_back(-30.0 + (0.99 + 30.0) * k / 20000.0);
    for (int k = 0; k <= 20000; ++k) qs.push_back(1.0 - 0.01 * std::pow(10.0, -12.0 * k / 20000.0));
    std::optional<double> previous;
    for (double q : qs) {
      const auto p = hb.at_q(q, branch);
      if (!p) {
        previous.reset();
        continue;
      }
      const double f = p->separation - l;
      if (previous && (*previous < 0) != (f < 0)) ++count;
      previous = f;
    }
  }
  return count;
}

TEST(Solutions, CountMatchesIndependentDenseScan) {
  for (double w : {0.995, 1.0, 1.005}) {
    const TappingModel model(Cantilever(1.0, 100.0), Drive(0.2, w), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), 0.0);
    const HarmonicBalance hb(model);
    for (double l : {-0.5, 0.0, 0.05, 0.15, 0.3, 1.0, 5.0, 14.0, 14.3, 14.6, 16.0, 19.0}) {
      EXPECT_EQ(static_cast<int>(hb.solutions(l).size()), dense_count(hb, l)) << "w=" << w << " l=" << l;
    }
  }
}

TEST(Solutions, BadInput) {
  const HarmonicBalance hb(example(1.0));
  EXPECT_THROW(hb.solutions(std::nan("")), InvalidParameter);
  // any other law has harmonic balance too (test_general_hb.cpp), but no closed-form coefficients
  const TappingModel dmt(Cantilever(1.0, 100.0), Drive(0.2, 1.0),
                         impact::ForceLaw(impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165)), 3.0);
  const HarmonicBalance general(dmt);
  EXPECT_FALSE(general.closed_form());
  EXPECT_TRUE(hb.closed_form());
  try {
    (void)general.coefficients();
    FAIL() << "expected InvalidParameter";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "law");
  }
  EXPECT_THROW(general.solutions(std::nan("")), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
