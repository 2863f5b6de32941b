// The table law's energy check (TableLaw::require_dissipative) over the whole domain of the law as it is
// evaluated: curves built to create energy in only one region each (between the knots, below the tables where the
// branches continue as straight lines, beyond the end of one table while the other continues, below one table
// while the other goes deeper). Each curve is first checked independently — its knots pass the old node test,
// and a dense evaluation of the law finds the region where H_b > H_a — and then must be refused. Accepted laws are
// checked independently by simulation: no impact they allow has a restitution above 1.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/force_law.hpp"
#include "afmkit/impact/impact.hpp"
#include "afmkit/impact/laws/table_law.hpp"

using afmkit::InvalidParameter;
using namespace afmkit::impact;

namespace {

ForceCurve curve(std::vector<double> xa, std::vector<double> ya, std::vector<double> xb, std::vector<double> yb) {
  ForceCurve c;
  c.origin = "built.csv";
  c.approach_gap = std::move(xa);
  c.approach_force = std::move(ya);
  c.retract_gap = std::move(xb);
  c.retract_force = std::move(yb);
  return c;
}

/// The old check: H_a ≥ H_b at the knots of both branches inside the range both tabulate.
bool nodes_pass(const ForceCurve& c) {
  const TableLaw law(c, true);
  const double lo = std::max(c.approach_gap.front(), c.retract_gap.front());
  const double hi = std::min(c.approach_gap.back(), c.retract_gap.back());
  for (const auto* xs : {&c.approach_gap, &c.retract_gap})
    for (double d : *xs)
      if (d >= lo && d <= hi && law.departure(d) > law.approach(d) + 1e-9) return false;
  return true;
}

/// The largest H_b − H_a found by evaluating the law on a dense grid of [lo, hi] (independent of the check).
struct Excess {
  double value = -INFINITY;
  double at = NAN;
};
Excess dense_excess(const ForceCurve& c, double lo, double hi) {
  const TableLaw law(c, true);
  Excess e;
  const int n = 200000;
  for (int k = 0; k <= n; ++k) {
    const double d = lo + (hi - lo) * k / n;
    const double x = law.departure(d) - law.approach(d);
    if (x > e.value) e = {x, d};
  }
  return e;
}

std::string refusal(const ForceCurve& c) {
  try {
    TableLaw(c).require_dissipative();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "force_curve");
    return e.what();
  }
  return "";
}

/// Largest restitution over head-on impacts from `gap` at a range of speeds (integrated; energy gain allowed so
/// that refused curves can be simulated too).
double largest_restitution(const ForceCurve& c, double gap, const std::vector<double>& speeds) {
  const ForceLaw law(std::make_shared<const TableLaw>(c, true));
  double worst = 0.0;
  for (double v : speeds) {
    const ImpactResult r = simulate_impact(ImpactProblem::head_on(1.0, 1.0, v, gap, law));
    if (r.outcome == ImpactOutcome::separated) worst = std::max(worst, r.restitution);
  }
  return worst;
}

const std::vector<double> speeds{0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0};

// Approach: the straight line H_a = −d on [−3, 1] (knots every 1 nm).
const std::vector<double> line_x{-3.0, -2.0, -1.0, 0.0, 1.0};
const std::vector<double> line_y{3.0, 2.0, 1.0, 0.0, -1.0};

}  // namespace

TEST(TableLawEnergy, BetweenKnotsTheInterpolantIsChecked) {
  // The retract knots lie below the approach line, but its PCHIP between −2 and −1 starts flat at −2 (the secant
  // to −3 is nearly 0) and stays above the line for a while.
  const ForceCurve c = curve(line_x, line_y, line_x, {2.0, 1.99, 0.99, -0.5, -1.5});
  ASSERT_TRUE(nodes_pass(c));
  const Excess e = dense_excess(c, -10.0, 5.0);
  ASSERT_GT(e.value, 0.05);
  ASSERT_GT(e.at, -2.0);
  ASSERT_LT(e.at, -1.0);
  const std::string m = refusal(c);
  EXPECT_NE(m.find("built.csv: the retract force"), std::string::npos) << m;
  EXPECT_NE(m.find("inside both tables"), std::string::npos) << m;
  EXPECT_NE(m.find("allow_energy_gain"), std::string::npos) << m;
  // the distance named is the largest excess of the interval, to the dense grid's resolution
  const auto at = m.find("at distance ");
  ASSERT_NE(at, std::string::npos) << m;
  EXPECT_NEAR(std::stod(m.substr(at + 12)), e.at, 1e-3) << m;
  // a cycle between the ends of that stretch gains energy (the law's own exact integral of H_a − H_b)
  EXPECT_LT(TableLaw(c, true).hysteresis_area(e.at - 0.05, e.at + 0.05), 0.0);
}

TEST(TableLawEnergy, ARetractStifferAtItsDeepestPointContinuesWithTheApproachSlope) {
  // Inside the tables the retract lies below the approach; its contact is stiffer at the deepest point (end slope
  // −1.55 against −1, as cells unload). Continued with its own slope its straight line would rise above the
  // approach's below −3.9 nm (an energy gain at depths never measured); the law continues it with the approach's
  // slope instead, so it stays a fixed 0.5 nN below the approach there, and the curve is accepted.
  const ForceCurve c = curve(line_x, line_y, line_x, {2.5, 1.2, 0.4, -0.1, -1.2});
  ASSERT_TRUE(nodes_pass(c));
  EXPECT_EQ(refusal(c), "");
  EXPECT_LE(dense_excess(c, -40.0, 5.0).value, 0.0);
  const TableLaw law(c);
  // independently of the law's coefficients: the lines through its values below the tables
  const double sa = law.approach(-10.0) - law.approach(-11.0), sb = law.departure(-10.0) - law.departure(-11.0);
  EXPECT_NEAR(sb, sa, 1e-12);
  EXPECT_NEAR(law.departure(-3.0), 2.5, 1e-12);  // the table's value at its deepest point, continuous there
  EXPECT_NEAR(law.approach(-25.0) - law.departure(-25.0), 0.5, 1e-12);
  // the kink at the retract's deepest point is a switching gap of the law
  const auto g = law.switching_gaps();
  EXPECT_NE(std::find(g.begin(), g.end(), -3.0), g.end());
  // the law's exact area below the tables: a 0.5 nN difference over 10 nm
  EXPECT_NEAR(law.hysteresis_area(-15.0, -5.0), 5.0, 1e-9);
  // every impact dissipates, however deep it goes
  EXPECT_LE(largest_restitution(c, 2.0, speeds), 1.0);
}

TEST(TableLawEnergy, BeyondTheApproachTableARepulsiveRetractIsChecked) {
  // The approach ends at 1 nm (0 beyond); the retract goes on to 3 nm and turns repulsive there.
  const ForceCurve c = curve(line_x, line_y, {-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0},
                             {2.0, 1.0, 0.0, -1.0, -1.5, 0.1, 0.5});
  ASSERT_TRUE(nodes_pass(c));
  EXPECT_LE(dense_excess(c, -40.0, 1.0).value, 0.0);
  ASSERT_GT(dense_excess(c, 1.0, 4.0).value, 0.4);
  const std::string m = refusal(c);
  EXPECT_NE(m.find("beyond the end of the approach table, where the approach force is 0"), std::string::npos) << m;
}

TEST(TableLawEnergy, BeyondTheRetractTableAnAttractiveApproachIsChecked) {
  // The retract ends at 0 nm (0 beyond); the approach is still attractive up to 1 nm: H_a = −1 < 0 = H_b.
  const ForceCurve c = curve(line_x, line_y, {-3.0, -2.0, -1.0, 0.0}, {2.0, 1.0, 0.0, -1.0});
  ASSERT_TRUE(nodes_pass(c));
  EXPECT_LE(dense_excess(c, -40.0, 0.0).value, 0.0);
  ASSERT_GT(dense_excess(c, 0.0, 2.0).value, 0.9);
  const std::string m = refusal(c);
  EXPECT_NE(m.find("exceeds the approach force -1 nN at distance 1 nm"), std::string::npos) << m;  // the largest excess
  EXPECT_NE(m.find("beyond the end of the retract table, where the retract force is 0"), std::string::npos) << m;
}

TEST(TableLawEnergy, BelowOneTableWhileTheOtherGoesDeeperIsChecked) {
  // The approach table starts at −3 nm (below: its line H_a = −d); the retract is tabulated down to −6 nm, above
  // that line at −5 and −4 nm (outside the range both tabulate), and softer than it at −6 nm (so below both tables
  // the retract stays below).
  const ForceCurve c = curve(line_x, line_y, {-6.0, -5.0, -4.0, -3.0, -2.0, -1.0, 0.0, 1.0},
                             {5.9, 5.4, 4.4, 2.9, 1.9, 0.9, -0.1, -1.1});
  EXPECT_LE(dense_excess(c, -60.0, -6.0).value, 0.0);
  ASSERT_TRUE(nodes_pass(c));
  EXPECT_LE(dense_excess(c, -3.0, 5.0).value, 0.0);
  ASSERT_GT(dense_excess(c, -6.0, -3.0).value, 0.4);
  const std::string m = refusal(c);
  EXPECT_NE(m.find("below the approach table, where the approach continues as a straight line"), std::string::npos)
      << m;
}

TEST(TableLawEnergy, AcceptedCurvesDissipateInEveryImpact) {
  // Curves the check accepts: by dense evaluation H_b ≤ H_a everywhere, and no simulated impact (shallow to far
  // beyond the tables) gains energy.
  const std::vector<ForceCurve> accepted{
      curve(line_x, line_y, line_x, {2.5, 1.5, 0.5, -0.5, -1.5}),                   // parallel, below
      curve(line_x, line_y, line_x, {2.1, 1.2, 0.3, -0.6, -1.5}),                   // softer contact
      curve(line_x, line_y, {-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0},                 // retract goes on, attractive
            {2.0, 1.0, 0.0, -1.0, -1.5, -0.5, 0.0}),
      curve({-3.0, -2.0, -1.0, 0.0, 1.0, 2.0}, {3.0, 2.0, 1.0, 0.0, 0.3, 0.0},      // approach goes on, repulsive
            line_x, {2.0, 1.0, 0.0, -1.0, -1.0}),
  };
  for (const ForceCurve& c : accepted) {
    EXPECT_NO_THROW(TableLaw(c).require_dissipative());
    EXPECT_LE(dense_excess(c, -60.0, 6.0).value, 1e-12);
    EXPECT_LE(largest_restitution(c, 4.0, speeds), 1.0 + 1e-6);
  }
}

TEST(TableLawEnergy, ExampleCurvesAreAccepted) {
  for (const char* name : {"dmt_adhesion.csv", "stiff_hertz_vdw.txt"}) {
    const ForceCurve c = read_force_curve(std::string(AFMKIT_SOURCE_DIR) + "/examples/force_curves/" + name);
    EXPECT_NO_THROW(TableLaw(c).require_dissipative()) << name;
  }
}
