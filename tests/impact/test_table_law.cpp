// The force law of a measured force curve (impact::TableLaw): the table reader (both layouts, units, every error
// with its line), the PCHIP interpolant (no overshoot, accuracy on a sampled DMT curve, agreement with Boost's
// pchip), the rules beyond the table, the dissipation check and the hysteresis area by quadrature.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <math.h>  // before Boost 1.74's pchip.hpp, which calls an unqualified isnan (::isnan from here)

#include <boost/math/interpolators/pchip.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/force_law.hpp"
#include "afmkit/impact/impact.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"
#include "afmkit/impact/laws/table_law.hpp"

using afmkit::InputError;
using afmkit::InvalidParameter;
using namespace afmkit::impact;

namespace {

/// The message of the InputError that parsing `text` throws ("" if it parses).
std::string parse_error(const std::string& text) {
  try {
    parse_force_curve(text, "curve.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_PARSE_ERROR(text, line, fragment)                                      \
  do {                                                                                \
    const std::string message_ = parse_error(text);                                   \
    EXPECT_EQ(message_.rfind(std::string("curve.csv:") + (line) + ":", 0), 0u) << message_; \
    EXPECT_NE(message_.find(fragment), std::string::npos) << message_;                \
  } while (0)

/// A curve with both branches on the same gaps.
ForceCurve sampled(const std::vector<double>& gaps, double (*fa)(double), double (*fb)(double)) {
  ForceCurve c;
  c.origin = "sampled";
  for (double d : gaps) {
    c.approach_gap.push_back(d);
    c.approach_force.push_back(fa(d));
    c.retract_gap.push_back(d);
    c.retract_force.push_back(fb(d));
  }
  return c;
}

std::vector<double> linspace(double lo, double hi, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = lo + (hi - lo) * i / (n - 1);
  return v;
}

const char* three_column =
    "# exported by an AFM\r\n"
    "\r\n"
    "distance (nm), approach (nN), retract (nN)\r\n"
    "4.0, 0.0, -0.1\r\n"
    "3.0, -0.5, -0.8\r\n"
    "# a comment inside the table\r\n"
    "2.0, 1.0, 0.5\r\n"
    "1.0, 4.0, 3.0\r\n"
    "0.0, 9.0, 7.5\r\n";

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------------------------------------------

TEST(ForceCurveParse, ThreeColumnCsvIsSortedAscending) {
  const ForceCurve c = parse_force_curve(three_column, "a.csv");
  EXPECT_EQ(c.origin, "a.csv");
  EXPECT_EQ(c.approach_gap, (std::vector<double>{0, 1, 2, 3, 4}));
  EXPECT_EQ(c.approach_force, (std::vector<double>{9, 4, 1, -0.5, 0}));
  EXPECT_EQ(c.retract_gap, c.approach_gap);
  EXPECT_EQ(c.retract_force, (std::vector<double>{7.5, 3, 0.5, -0.8, -0.1}));
}

TEST(ForceCurveParse, FourColumnsBlankSeparatedInAngstromAndPiconewton) {
  // the approach far to near, the retract near to far and shorter (its trailing cells left out)
  const char* text =
      "approach distance [Å]  approach force [pN]  retract distance (A)  retract force_pN\n"
      "  40   -10     -10   25000\n"
      "  30   -20       0    9000\n"
      "  20   -40      10    -500\n"
      "  10  -100      20     -60\n"
      "   0  4000\n"
      " -10 30000\n";
  const ForceCurve c = parse_force_curve(text, "b.txt");
  ASSERT_EQ(c.approach_gap.size(), 6u);
  ASSERT_EQ(c.retract_gap.size(), 4u);
  EXPECT_DOUBLE_EQ(c.approach_gap.front(), -1.0);
  EXPECT_DOUBLE_EQ(c.approach_gap.back(), 4.0);
  EXPECT_DOUBLE_EQ(c.approach_force.front(), 30.0);
  EXPECT_DOUBLE_EQ(c.approach_force.back(), -0.01);
  EXPECT_DOUBLE_EQ(c.retract_gap.front(), -1.0);
  EXPECT_DOUBLE_EQ(c.retract_gap.back(), 2.0);
  EXPECT_DOUBLE_EQ(c.retract_force.front(), 25.0);
  EXPECT_DOUBLE_EQ(c.retract_force.back(), -0.06);
}

TEST(ForceCurveParse, FourColumnsInAnyOrderWithABranchStartingLater) {
  // semicolon separated, quoted cells, columns shuffled; the approach branch starts at the second row
  const char* text =
      "\"retract force (nN)\";\"extend force (nN)\";\"extend z (nm)\";\"retract z (nm)\"\n"
      "1;;;0\n"
      "2;5;1;1\n"
      "3;6;2;2\n"
      "4;7;3;3\n"
      "5;8;4;4\n";
  const ForceCurve c = parse_force_curve(text, "c.csv");
  EXPECT_EQ(c.retract_gap, (std::vector<double>{0, 1, 2, 3, 4}));
  EXPECT_EQ(c.retract_force, (std::vector<double>{1, 2, 3, 4, 5}));
  EXPECT_EQ(c.approach_gap, (std::vector<double>{1, 2, 3, 4}));
  EXPECT_EQ(c.approach_force, (std::vector<double>{5, 6, 7, 8}));
}

TEST(ForceCurveParse, UnitSpellingsAndSeparators) {
  struct Case {
    const char* distance;
    double to_nm;
    const char* force;
    double to_nn;
  };
  const Case cases[] = {
      {"separation [nm]", 1.0, "trace [nN]", 1.0},          {"gap_nm", 1.0, "approach_force_pN", 1e-3},
      {"z (um)", 1e3, "approach (uN)", 1e3},                {"z (\xC2\xB5m)", 1e3, "approach (\xC2\xB5N)", 1e3},
      {"z (\xCE\xBCm)", 1e3, "approach (\xCE\xBCN)", 1e3},  {"distance (m)", 1e9, "approach (N)", 1e9},
      {"distance (angstrom)", 0.1, "approach (pN)", 1e-3},  {"distance (\xE2\x84\xAB)", 0.1, "approach (nN)", 1.0},
  };
  for (const Case& k : cases) {
    for (const char* sep : {",", ";", "\t"}) {
      const std::string retract = std::string("retract (nN)");
      std::string text = std::string(k.distance) + sep + k.force + sep + retract + "\n";
      for (int i = 0; i < 4; ++i)
        text += std::to_string(i) + sep + std::to_string(10 * i) + sep + std::to_string(-i) + "\n";
      const ForceCurve c = parse_force_curve(text, "u.csv");
      SCOPED_TRACE(text);
      EXPECT_DOUBLE_EQ(c.approach_gap[3], 3 * k.to_nm);
      EXPECT_DOUBLE_EQ(c.approach_force[2], 20 * k.to_nn);
      EXPECT_DOUBLE_EQ(c.retract_force[3], -3.0);
    }
  }
  // blank separated header of multi-word columns, a UTF-8 byte-order mark, '+' signs and exponents
  const ForceCurve c = parse_force_curve(
      "\xEF\xBB\xBF"
      "tip sample distance (nm)   approach force (nN)   retract force (nN)\n"
      "+1e0 2 +3\n2.5e0 4 5\n3.0 6 7\n4 8 9.5E-1\n",
      "v.txt");
  EXPECT_EQ(c.approach_gap, (std::vector<double>{1, 2.5, 3, 4}));
  EXPECT_EQ(c.retract_force, (std::vector<double>{3, 5, 7, 0.95}));
}

TEST(ForceCurveParse, EveryBadInputNamesTheFileAndLine) {
  const std::string header = "distance (nm), approach (nN), retract (nN)\n";
  const std::string rows = "0, 3, 2\n1, 2, 1\n2, 1, 0\n3, 0, 0\n";
  // no header at all, or a first line of numbers
  EXPECT_PARSE_ERROR("# only a comment\n\n", "2", "no header line");
  EXPECT_PARSE_ERROR("", "1", "no header line");
  EXPECT_PARSE_ERROR("1, 2, 3\n" + rows, "1", "no header line");
  // header without units, with an unknown unit, ambiguous or incomplete
  EXPECT_PARSE_ERROR("distance, approach, retract\n" + rows, "1", "has no unit");
  EXPECT_PARSE_ERROR("# c\ndistance (nm), approach (nN), retract\n" + rows, "2", "'retract' has no unit");
  EXPECT_PARSE_ERROR("distance (furlong), approach (nN), retract (nN)\n" + rows, "1", "unknown unit 'furlong'");
  EXPECT_PARSE_ERROR("distance [nm], approach [kN], retract [nN]\n" + rows, "1", "unknown unit 'kN'");
  EXPECT_PARSE_ERROR("distance (nm), force (nN), retract (nN)\n" + rows, "1", "does not say its branch");
  EXPECT_PARSE_ERROR("distance (nN), approach (nN), retract (nN)\n" + rows, "1", "is called a distance");
  // a missing branch
  EXPECT_PARSE_ERROR("distance (nm), approach (nN)\n0, 1\n1, 2\n2, 3\n3, 4\n", "1", "the retract branch is missing");
  EXPECT_PARSE_ERROR("distance (nm), retract (nN), retract force (nN)\n" + rows, "1", "same role");
  EXPECT_PARSE_ERROR("approach distance (nm), approach force (nN), retract force (nN)\n" + rows, "1",
                     "no retract distance column");
  // bad cells
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, nan, 1\n2, 1, 0\n3, 0, 0\n", "3", "'nan' is not a finite number");
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, 2, 1\n2, 1, -inf\n3, 0, 0\n", "4", "'-inf' is not a finite number");
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, 2, 1\n2, 1, 0\n3, 0x1, 0\n", "5", "'0x1' is not a number");
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, 2, 1\n2, 1e999, 0\n3, 0, 0\n", "4", "'1e999' is not a number");
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, 2 nN, 1\n", "3", "'2 nN' is not a number");
  EXPECT_PARSE_ERROR("distance (m), approach (nN), retract (nN)\n0, 3, 2\n1e305, 2, 1\n", "3", "overflows");
  // wrong number of cells
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, 2, 1, 7\n", "3", "4 cells, but the header (line 1) has 3 columns");
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, 2\n", "3", "2 cells, but the header");
  EXPECT_PARSE_ERROR("distance (nm)  approach (nN)  retract (nN)\n0 3 2\n1 2 1 0\n", "3", "4 cells");
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n, 2, 1\n", "3", "distance cell");
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, , \n", "3", "both force cells are empty");
  EXPECT_PARSE_ERROR("approach distance (nm), approach force (nN), retract distance (nm), retract force (nN)\n"
                     "0, 3, 0, 2\n1, , 1, 1\n",
                     "3", "approach distance is given but its force cell is empty");
  // unsorted: duplicate and non-monotone distances
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, 2, 1\n1, 1, 0\n3, 0, 0\n", "4", "duplicate approach distance 1 nm (also at line 3)");
  EXPECT_PARSE_ERROR(header + "3, 0, 0\n2, 1, 0\n2.5, 2, 1\n0, 3, 2\n", "4", "breaks the descending order");
  EXPECT_PARSE_ERROR("approach distance (nm), approach force (nN), retract distance (nm), retract force (nN)\n"
                     "0, 3, 0, 2\n1, 2, 1, 1\n2, 1, 0.5, 0\n",
                     "4", "retract distance 0.5 nm breaks the ascending order");
  // a branch that stops and resumes
  EXPECT_PARSE_ERROR(header + "0, 3, 2\n1, 2, \n2, 1, 0\n", "4", "the retract branch resumes after it ended at line 3");
  // too few points (reported at the header line), or no rows at all
  EXPECT_PARSE_ERROR("# c\n" + header + "0, 3, 2\n1, 2, 1\n2, 1, 0\n", "2", "the approach branch has 3 points: at least 4");
  EXPECT_EQ(parse_error(header + rows + "4, 0, \n"), "");  // parses: the retract ends earlier
  EXPECT_PARSE_ERROR(header + "0, 3, \n1, 2, \n2, 1, 0\n3, 0, 0\n4, 0, 0\n", "1", "the retract branch has 3 points");
  EXPECT_PARSE_ERROR("# c\n" + header + "\n# nothing\n", "2", "no data rows");
}

TEST(ForceCurveParse, MissingFileIsAnInputErrorNamingIt) {
  try {
    read_force_curve("/nonexistent/curve.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open force curve '/nonexistent/curve.csv': No such file or directory"), std::string::npos) << e.what();
  }
}

TEST(ForceCurveParse, ExampleFilesParseAndDissipate) {
  const std::string dir = std::string(AFMKIT_SOURCE_DIR) + "/examples/force_curves/";
  const ForceCurve a = read_force_curve(dir + "dmt_adhesion.csv");
  EXPECT_EQ(a.approach_gap.size(), 200u);
  EXPECT_DOUBLE_EQ(a.approach_gap.front(), -3.0);
  EXPECT_DOUBLE_EQ(a.approach_gap.back(), 15.0);
  const ForceCurve b = read_force_curve(dir + "stiff_hertz_vdw.txt");
  EXPECT_EQ(b.approach_gap.size(), 140u);
  EXPECT_EQ(b.retract_gap.size(), 180u);
  EXPECT_DOUBLE_EQ(b.retract_gap.back(), 12.0);  // 120 Å
  EXPECT_DOUBLE_EQ(b.approach_gap.front(), -1.5);  // -15 Å
  EXPECT_NEAR(b.approach_force.front(), 38.46193487, 1e-9);  // 38461.93487 pN
  for (const ForceCurve& c : {a, b}) {
    const ForceLaw law = make_law<TableLaw>(c);
    EXPECT_NO_THROW(law.require_dissipative());
    EXPECT_GT(hysteresis_energy_loss(law, c.approach_gap.front(), 20.0), 0.0);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// The interpolant
// ---------------------------------------------------------------------------------------------------------------

TEST(TableLaw, MonotoneDataStaysMonotoneAndNeverOvershoots) {
  // a jump-to-contact cliff, flat stretches, and unevenly spaced knots: a plain cubic spline rings here
  const std::vector<double> x{-2.0, -1.5, -1.4, -1.0, -0.2, 0.0, 0.05, 0.1, 0.8, 1.0, 3.0, 3.1, 6.0};
  const std::vector<double> y{40.0, 30.0, 29.9, 12.0, 2.0, 2.0, 2.0, -3.0, -3.0, -2.5, -0.2, -0.2, 0.0};
  ForceCurve c;
  c.approach_gap = c.retract_gap = x;
  c.approach_force = y;
  c.retract_force = y;
  const TableLaw law(c);
  for (std::size_t i = 0; i + 1 < x.size(); ++i) {
    const double lo = std::min(y[i], y[i + 1]), hi = std::max(y[i], y[i + 1]);
    const double tol = 1e-12 * (1.0 + std::max(std::abs(lo), std::abs(hi)));
    double previous = law.approach(x[i]);
    EXPECT_EQ(previous, y[i]);
    for (int k = 1; k <= 2000; ++k) {
      const double d = x[i] + (x[i + 1] - x[i]) * k / 2000.0;
      const double f = law.approach(d);
      ASSERT_GE(f, lo - tol) << "overshoot at d = " << d;
      ASSERT_LE(f, hi + tol) << "overshoot at d = " << d;
      // monotone in the direction of the data on every interval
      if (y[i + 1] >= y[i]) {
        ASSERT_GE(f, previous - tol) << d;
      }
      if (y[i + 1] <= y[i]) {
        ASSERT_LE(f, previous + tol) << d;
      }
      if (d < x.back()) previous = f;
    }
  }
}

TEST(TableLaw, InteriorAgreesWithBoostPchip) {
  // Boost 1.74's pchip uses the same Fritsch–Butland interior slopes (it differs only in the two end slopes, where
  // it takes the one-sided secant), so away from the end intervals both interpolants coincide.
  const std::vector<double> x{-1.0, -0.7, -0.3, 0.0, 0.2, 0.9, 1.4, 2.0, 3.5, 4.0};
  const std::vector<double> y{9.0, 5.0, 2.5, 1.0, -0.5, -1.2, -0.4, -0.45, -0.1, 0.0};
  ForceCurve c;
  c.approach_gap = c.retract_gap = x;
  c.approach_force = c.retract_force = y;
  const TableLaw law(c);
  auto xs = x, ys = y;
  const boost::math::interpolators::pchip<std::vector<double>> reference(std::move(xs), std::move(ys));
  for (double d = x[2]; d <= x[x.size() - 3]; d += 1e-3) EXPECT_NEAR(law.approach(d), reference(d), 1e-12) << d;
}

TEST(TableLaw, ReproducesASampledDmtCurveBetweenTheKnots) {
  // 200 evenly spaced samples over [−5, 20] nm (h ≈ 0.126 nm) of the DMT law, evaluated at 63 points inside every
  // interval. Measured (g++ 12, x86-64): |error| / max|F| = 2.6e-5 away from the contact edge a0 = 0.165 nm
  // (|d − a0| > 2h), 1.1e-2 within 2h of it, where the DMT slope jumps from 0 to A R/(3 a0³) ≈ 470 nN/nm (a slope
  // jump between two knots is not resolved by any C¹ interpolant); pointwise relative error 1.2e-5 in contact
  // where |F| > 0.1 max|F|, 1.4e-3 on the van der Waals tail.
  static const DmtLaw dmt(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165);
  const std::vector<double> gaps = linspace(-5.0, 20.0, 200);
  const ForceCurve curve = sampled(gaps, [](double d) { return dmt.approach(d); }, [](double d) { return dmt.departure(d); });
  const TableLaw law(curve);
  const double a0 = 0.165, h = gaps[1] - gaps[0];
  double fmax = 0.0;
  for (double f : curve.approach_force) fmax = std::max(fmax, std::abs(f));
  double far_error = 0.0, edge_error = 0.0, contact_rel = 0.0, tail_rel = 0.0;
  for (std::size_t i = 0; i + 1 < gaps.size(); ++i) {
    for (int k = 1; k < 64; ++k) {
      const double d = gaps[i] + h * k / 64.0;
      for (bool approach : {true, false}) {
        const double exact = approach ? dmt.approach(d) : dmt.departure(d);
        const double error = std::abs((approach ? law.approach(d) : law.departure(d)) - exact);
        if (std::abs(d - a0) > 2 * h) {
          far_error = std::max(far_error, error / fmax);
          if (d > a0) tail_rel = std::max(tail_rel, error / std::abs(exact));
          if (d < a0 && std::abs(exact) > 0.1 * fmax) contact_rel = std::max(contact_rel, error / std::abs(exact));
        } else {
          edge_error = std::max(edge_error, error / fmax);
        }
      }
    }
  }
  EXPECT_LT(far_error, 5e-5);
  EXPECT_LT(edge_error, 2e-2);
  EXPECT_LT(contact_rel, 3e-5);
  EXPECT_LT(tail_rel, 3e-3);
  // exact at the knots
  for (std::size_t i = 0; i < gaps.size(); ++i) EXPECT_EQ(law.approach(gaps[i]), curve.approach_force[i]);
}

// ---------------------------------------------------------------------------------------------------------------
// Beyond the table, switching gaps
// ---------------------------------------------------------------------------------------------------------------

TEST(TableLaw, BelowTheTableContinuesLinearlyAboveItIsZero) {
  ForceCurve c = parse_force_curve(three_column, "a.csv");
  c.retract_gap.pop_back();  // retract ends at 3 nm, approach at 4 nm
  c.retract_force.pop_back();
  const TableLaw law(c, false, Hysteresis::velocity);  // (contact-aware: also the contact and release gaps)
  // above each branch's largest distance: 0; at it: the tabulated value
  EXPECT_EQ(law.approach(4.0), 0.0);
  EXPECT_EQ(law.approach(4.0 + 1e-12), 0.0);
  EXPECT_EQ(law.departure(3.0), -0.8);
  EXPECT_EQ(law.departure(3.0 + 1e-12), 0.0);
  EXPECT_EQ(law.departure(100.0), 0.0);
  // below the smallest distance: the straight line with the interpolant's end value and slope (C¹)
  const double eps = 1e-6;
  for (bool approach : {true, false}) {
    auto f = [&](double d) { return approach ? law.approach(d) : law.departure(d); };
    const double inside_slope = (f(eps) - f(0.0)) / eps;  // one-sided difference inside the table
    const double slope = f(-1.0) - f(-2.0);
    EXPECT_NEAR(f(-1.0) - f(0.0), -slope, 1e-12);
    EXPECT_NEAR(f(-7.5) - f(0.0), -7.5 * slope, 1e-11);
    EXPECT_NEAR(inside_slope, slope, 1e-4 * std::abs(slope));
    EXPECT_LT(slope, 0.0);  // deeper indentation pushes harder
    EXPECT_NEAR(f(-eps), f(0.0) - eps * slope, 1e-12);
  }
  // the jump to zero at each branch's end is a switching gap; above the highest the branches coincide
  EXPECT_EQ(law.switching_gaps(), (std::vector<double>{3.0, 4.0}));
  EXPECT_TRUE(law.branch_dependent(0));
  EXPECT_TRUE(law.branch_dependent(1));
  EXPECT_FALSE(law.branch_dependent(2));
  const ForceLaw wrapped = make_law<TableLaw>(parse_force_curve(three_column, "a.csv"), false, Hysteresis::velocity);
  EXPECT_EQ(wrapped.switching_gaps(), std::vector<double>{4.0});
  EXPECT_EQ(wrapped.name(), "table");
}

TEST(TableLaw, ConstructorRejectsBadTables) {
  const ForceCurve good = parse_force_curve(three_column, "a.csv");
  auto rejects = [](ForceCurve c, const std::string& fragment) {
    try {
      TableLaw law(std::move(c));
      ADD_FAILURE() << "accepted; expected " << fragment;
    } catch (const InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), "force_curve");
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  ForceCurve c = good;
  c.retract_force[2] = std::nan("");
  rejects(c, "is not finite");
  c = good;
  c.approach_gap[3] = std::numeric_limits<double>::infinity();
  rejects(c, "is not finite");
  c = good;
  std::swap(c.approach_gap[1], c.approach_gap[2]);
  rejects(c, "strictly ascending");
  c = good;
  c.retract_gap.pop_back();
  rejects(c, "5 forces");
  c = good;
  c.approach_gap.resize(3);
  c.approach_force.resize(3);
  rejects(c, "at least 4");
  c = good;
  c.approach_gap[1] = c.approach_gap[0] + 1e-310;  // the secant overflows
  rejects(c, "overflows");
}

// ---------------------------------------------------------------------------------------------------------------
// Dissipation and the hysteresis area
// ---------------------------------------------------------------------------------------------------------------

TEST(TableLaw, RequireDissipativeAcceptsHaAboveHbAndRejectsTheOpposite) {
  const ForceCurve good = parse_force_curve(three_column, "a.csv");
  EXPECT_NO_THROW(TableLaw(good).require_dissipative());
  ForceCurve same = good;
  same.retract_force = same.approach_force;  // conservative: H_a = H_b
  EXPECT_NO_THROW(TableLaw(same).require_dissipative());
  same.retract_force[1] += 1e-12;  // within the tolerance 1e-9 max|F|
  EXPECT_NO_THROW(TableLaw(same).require_dissipative());

  ForceCurve bad = good;
  bad.retract_force[2] = 1.5;  // > approach 1.0 at 2 nm
  bad.retract_force[3] = 0.0;  // > approach −0.5 at 3 nm
  try {
    TableLaw(bad).require_dissipative();
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "force_curve");
    const std::string m = e.what();
    EXPECT_NE(m.find("a.csv: the retract force 1.5 nN exceeds the approach force 1 nN at distance 2 nm"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("allow_energy_gain"), std::string::npos) << m;
  }
  EXPECT_NO_THROW(TableLaw(bad, true).require_dissipative());
  EXPECT_NO_THROW(ForceLaw(std::make_shared<const TableLaw>(bad, true)).require_dissipative());
  EXPECT_THROW(make_law<TableLaw>(bad).require_dissipative(), InvalidParameter);

  // nodes of the retract branch between the approach knots are checked too; outside the common range not
  ForceCurve offset = good;
  offset.retract_gap = {-1.0, 0.5, 1.5, 2.5, 10.0};
  offset.retract_force = {12.0, 6.0, 3.0, 0.0, 0.0};  // at 1.5 nm the approach is ≈ 2.4 < 3
  EXPECT_THROW(TableLaw(offset).require_dissipative(), InvalidParameter);
  offset.retract_force = {12.0, 6.0, 0.0, -1.0, 0.0};  // −1 <= H_a everywhere in [0, 4]
  EXPECT_NO_THROW(TableLaw(offset).require_dissipative());
}

TEST(TableLaw, HysteresisAreaMatchesThePiecewiseLinearLaw) {
  // The piecewise-linear law (seed-1 eq. 26) tabulated on [−2, 0] with the contact-edge values taken from inside
  // (d → 0⁻) is reproduced exactly: PCHIP keeps straight lines straight, the linear continuation below −2
  // is the law itself, and the jump to 0 above 0 is the law's contact edge.
  static const PiecewiseLinearLaw pl(10.0, 6.0, 0.3, 0.8);
  auto fa = [](double d) { return -(pl.approach_adhesion + pl.approach_stiffness * d); };
  auto fb = [](double d) { return -(pl.departure_adhesion + pl.departure_stiffness * d); };
  const ForceCurve curve = sampled(linspace(-2.0, 0.0, 41), +fa, +fb);
  const auto model = std::make_shared<const TableLaw>(curve);
  const ForceLaw table(model);
  const ForceLaw exact(pl);
  for (int k = 0; k < 400; ++k) {
    const double d = -3.0 + 0.01 * k + 0.005;  // (at d = 0 exactly the table holds the left limit)
    EXPECT_NEAR(table.approach(d), exact.approach(d), 1e-12) << d;
    EXPECT_NEAR(table.departure(d), exact.departure(d), 1e-12) << d;
  }
  EXPECT_NO_THROW(table.require_dissipative());
  // The same branches as a custom law: hysteresis_energy_loss then takes its generic adaptive quadrature.
  CustomLaw custom;
  custom.approach = [model](double d) { return model->approach(d); };
  custom.departure = [model](double d) { return model->departure(d); };
  custom.switching_gaps = model->switching_gaps();
  const ForceLaw quadrature(custom);
  for (auto [lo, hi] : {std::pair{-1.5, 0.0}, {-2.0, 5.0}, {-3.0, 1.0}, {-0.25, -0.1}}) {
    const double analytic = hysteresis_energy_loss(exact, lo, hi);  // closed form of the piecewise-linear law
    EXPECT_NEAR(hysteresis_energy_loss(quadrature, lo, hi), analytic, 1e-10 * std::abs(analytic)) << lo << " " << hi;
    EXPECT_NEAR(hysteresis_energy_loss(table, lo, hi), analytic, 1e-12 * std::abs(analytic)) << lo << " " << hi;
  }
  // (F_b − F_a)δ + ½(K_a − K_b)δ² at δ = 1.5
  EXPECT_NEAR(hysteresis_energy_loss(table, -1.5, 0.0), 0.5 * 1.5 + 0.5 * 4.0 * 1.5 * 1.5, 1e-12);
  EXPECT_EQ(hysteresis_energy_loss(table, 0.5, 3.0), 0.0);  // above the table both branches are 0
}

TEST(TableLaw, HysteresisAreaOfASampledDmtCurve) {
  // DMT with hysteresis (softer retract contact, more retract adhesion), 200 samples over [−5, 20] nm: the exact
  // integral of the interpolant against the DMT closed form, and against the generic adaptive quadrature of the
  // same interpolant (a custom law) on a stretch of contact where that converges — over the whole table it does
  // not (the integrand is only C¹ at each knot and steep near a0), hence TableLaw's own hysteresis_area.
  // Measured relative differences: 4.2e-4 over [−5, 20] (the unresolved slope jump of DMT at a0), 8.6e-8 over
  // [−5, −1]; quadrature vs exact 1e-15.
  static const DmtLaw dmt(1.0, 0.8, 10.0, 6.4e-20, 9e-20, 0.165);
  const auto model = std::make_shared<const TableLaw>(
      sampled(linspace(-5.0, 20.0, 200), [](double d) { return dmt.approach(d); },
              [](double d) { return dmt.departure(d); }));
  const ForceLaw table(model), exact(dmt);
  EXPECT_NO_THROW(table.require_dissipative());
  const double whole = hysteresis_energy_loss(exact, -5.0, 20.0);
  EXPECT_NEAR(hysteresis_energy_loss(table, -5.0, 20.0), whole, 1e-3 * whole);
  const double contact = hysteresis_energy_loss(exact, -5.0, -1.0);
  const double part = hysteresis_energy_loss(table, -5.0, -1.0);
  EXPECT_NEAR(part, contact, 1e-6 * contact);
  CustomLaw custom;
  custom.approach = [model](double d) { return model->approach(d); };
  custom.departure = [model](double d) { return model->departure(d); };
  custom.switching_gaps = model->switching_gaps();
  EXPECT_NEAR(hysteresis_energy_loss(ForceLaw(custom), -5.0, -1.0), part, 1e-12 * part);
}

TEST(TableLaw, ContactGapIsTheBottomOfTheAdhesionWell) {
  // DMT's approach force is most negative at the contact edge a0: a table through a0 puts its contact there
  const afmkit::impact::DmtLaw dmt(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165);
  afmkit::impact::ForceCurve c;
  for (int i = 0; i <= 40; ++i) {
    const double d = -1.835 + 0.05 * i;  // a0 = 0.165 is the 41st-but-one … sample: -1.835 + 0.05·40 = 0.165
    c.approach_gap.push_back(d);
    c.approach_force.push_back(dmt.approach(d));
  }
  for (int i = 1; i <= 20; ++i) {
    c.approach_gap.push_back(0.165 + 0.25 * i);
    c.approach_force.push_back(dmt.approach(0.165 + 0.25 * i));
  }
  c.retract_gap = c.approach_gap;
  c.retract_force = c.approach_force;
  const afmkit::impact::TableLaw law(c);
  EXPECT_NEAR(law.contact_gap(), 0.165, 1e-12);
  // purely repulsive: the largest distance with a positive force
  afmkit::impact::ForceCurve r;
  r.approach_gap = r.retract_gap = {-2.0, -1.0, 0.0, 1.0};
  r.approach_force = r.retract_force = {4.0, 1.0, 0.0, 0.0};
  EXPECT_EQ(afmkit::impact::TableLaw(r).contact_gap(), -1.0);
}
