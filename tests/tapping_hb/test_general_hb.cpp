// Harmonic balance for any force law (general_harmonic_balance.hpp): the DMT + vdW case of the issue (k = 40 N/m,
// f0 = 300 kHz, Q = 400, A_free = 10 nm, R = 10 nm, E* = 1 GPa, A_H = 6.4e-20 J, a0 = 0.165 nm) against the
// balance equations with independent quadrature and an independent dense scan, its folds by finite differences,
// the other built-in laws, and the general algorithm applied to piecewise-linear laws against the closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>

#include <Eigen/Dense>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"
#include "afmkit/tapping/harmonic_balance.hpp"
#include "afmkit/tapping/numerical_describing_functions.hpp"
#include "afmkit/tapping/units.hpp"
#include "../counting_stop.hpp"
#include "reference.hpp"

namespace afmkit::tapping {
namespace {

using impact::PiecewiseLinearLaw;
using std::numbers::pi;

impact::ForceLaw normalised(const impact::ForceLaw& law) { return law.scaled(1.0 / 40.0, 2.0 * pi * 3e5); }

TappingModel physical(const impact::ForceLaw& law, double ratio = 1.0, double l = 8.0) {
  const PhysicalCantilever pc(40.0, 300.0, 400.0, 10.0, ratio);
  return TappingModel(pc.cantilever(), pc.drive(), normalised(law), l);
}

TappingModel dmt_model(double ratio = 1.0) { return physical(impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165), ratio); }

// max |scaled residual| of the balance equations (17) with the reference (Gauss–Kronrod) describing functions
double residual(const TappingModel& model, const HbPoint& p) {
  const auto r = test::balance_residual(model.with_separation(p.separation), p.offset, p.amplitude, p.phase);
  return std::max({std::abs(r[0]), std::abs(r[1]), std::abs(r[2])});
}

const HarmonicBalance& dmt_balance() {
  static const HarmonicBalance hb(dmt_model());
  return hb;
}

TEST(GeneralHarmonicBalance, DmtSolutionsSatisfyTheBalanceEquations) {
  const TappingModel model = dmt_model();
  const HarmonicBalance& hb = dmt_balance();
  EXPECT_FALSE(hb.closed_form());
  double worst = 0;
  int n = 0;
  for (const double l : {30.0, 12.0, 10.0, 9.5, 9.0, 8.8, 8.5, 8.0, 6.0, 5.0, 2.0, 1.0, 0.5, 0.2, 0.0, -0.1, -0.5, -2.0}) {
    const std::vector<HbPoint> s = hb.solutions(l);
    ASSERT_FALSE(s.empty()) << "l=" << l;
    for (std::size_t k = 0; k < s.size(); ++k) {
      const double r = residual(model, s[k]);
      EXPECT_LE(r, 1e-10) << "l=" << l << " B=" << s[k].amplitude;
      EXPECT_NEAR(s[k].separation, l, 1e-12 * std::max(1.0, std::abs(l)));
      EXPECT_NEAR(s[k].q, (s[k].offset + l) / s[k].amplitude, 1e-12 * std::max(1.0, std::abs(s[k].q)));
      if (k > 0) {
        EXPECT_GT(s[k].amplitude, s[k - 1].amplitude);  // sorted, no duplicates
      }
      // Free: out of contact (g − B ≥ a0) on the branch continuing the free oscillation
      if (s[k].branch == HbBranch::Free) {
        EXPECT_GE(s[k].offset + l - s[k].amplitude, 0.165 - 1e-12);
      }
      worst = std::max(worst, r);
      ++n;
    }
  }
  // far away: one solution, the free one, with B ≈ Γ|L(iω)|, A ≈ 0 (vdW at ≥ 1000 nm)
  const std::vector<HbPoint> far = hb.solutions(1000.0);
  ASSERT_EQ(far.size(), 1u);
  EXPECT_EQ(far[0].branch, HbBranch::Free);
  EXPECT_NEAR(far[0].amplitude, hb.free_amplitude(), 1e-9 * hb.free_amplitude());
  EXPECT_NEAR(far[0].offset, 0.0, 1e-8);
  std::printf("[ general HB ] DMT: %d solutions, worst balance residual %.2e\n", n, worst);
}

// Independent dense scan at fixed l: a grid in (g, B) of the mean-balance residual R1 = g − l − A(g, B) and of
// R2 = |L⁻¹ + N1|B − Γ (numerical describing functions, validated on their own in test_numerical_df.cpp); every
// cell where R2 changes sign and R1 changes sign in the cell or a neighbour seeds a damped Newton on (R1, R2) in
// (g, B). The converged roots (checked with the reference quadrature) must be exactly the library's solutions.
TEST(GeneralHarmonicBalance, DmtSolutionsAreEveryRootOfAnIndependentDenseScan) {
  const TappingModel model = dmt_model();
  const HarmonicBalance& hb = dmt_balance();
  const DescribingFunctionQuadrature df(model.law, model.drive.frequency);
  const std::complex<double> inverse = 1.0 / model.cantilever.transfer({0.0, model.drive.frequency});
  const double gamma = model.drive.amplitude, l0 = model.cantilever.static_gain();
  const int ng = 60, nb = 160;
  const double b_lo = 0.05, b_hi = 10.2;
  for (const double l : {9.6, 9.0, 8.5, 8.0, 6.0, 2.0, 0.5, -0.3}) {
    auto residuals = [&](double g, double b, double& r1, double& r2) {
      const DescribingFunctions d = df.at_gap(g, b);
      r1 = g - l + l0 * d.mean;  // g − l − A
      r2 = (std::abs(b * (inverse + d.first_harmonic)) - gamma) / gamma;
    };
    std::vector<double> gs(ng), bs(nb), r1(ng * nb), r2(ng * nb);
    for (int i = 0; i < ng; ++i) gs[i] = l - 0.15 + 0.25 * i / (ng - 1);
    for (int j = 0; j < nb; ++j) bs[j] = b_lo * std::pow(b_hi / b_lo, static_cast<double>(j) / (nb - 1));
    for (int i = 0; i < ng; ++i)
      for (int j = 0; j < nb; ++j) residuals(gs[i], bs[j], r1[i * nb + j], r2[i * nb + j]);
    auto changes = [&](const std::vector<double>& r, int i, int j) {
      if (i < 0 || j < 0 || i + 1 >= ng || j + 1 >= nb) return false;
      const double a = r[i * nb + j], b = r[(i + 1) * nb + j], c = r[i * nb + j + 1], d = r[(i + 1) * nb + j + 1];
      return std::min({a, b, c, d}) < 0.0 && std::max({a, b, c, d}) > 0.0;
    };
    struct Root {
      double g, b;
    };
    std::vector<Root> found;
    for (int i = 0; i + 1 < ng; ++i)
      for (int j = 0; j + 1 < nb; ++j) {
        if (!changes(r2, i, j)) continue;
        bool near = false;
        for (int di = -1; di <= 1; ++di)
          for (int dj = -1; dj <= 1; ++dj) near = near || changes(r1, i + di, j + dj);
        if (!near) continue;
        // damped Newton in (g, B) with a finite-difference Jacobian
        double g = 0.5 * (gs[i] + gs[i + 1]), b = std::sqrt(bs[j] * bs[j + 1]);
        double f1, f2;
        residuals(g, b, f1, f2);
        bool converged = false;
        for (int it = 0; it < 60 && !converged; ++it) {
          const double hg = 1e-8, hb_ = 1e-8 * b;
          double a1, a2, c1, c2;
          residuals(g + hg, b, a1, a2);
          residuals(g, b + hb_, c1, c2);
          const double j11 = (a1 - f1) / hg, j12 = (c1 - f1) / hb_, j21 = (a2 - f2) / hg, j22 = (c2 - f2) / hb_;
          const double det = j11 * j22 - j12 * j21;
          if (!(std::abs(det) > 0.0)) break;
          const double dg = -(j22 * f1 - j12 * f2) / det, db = -(-j21 * f1 + j11 * f2) / det;
          double lambda = 1.0;
          bool accepted = false;
          for (int k = 0; k < 30 && !accepted; ++k, lambda *= 0.5) {
            const double gt = g + lambda * dg, bt = b + lambda * db;
            if (!(bt > 0.0)) continue;
            double t1, t2;
            residuals(gt, bt, t1, t2);
            if (std::hypot(t1, t2) < (1.0 - 1e-4 * lambda) * std::hypot(f1, f2)) {
              g = gt;
              b = bt;
              f1 = t1;
              f2 = t2;
              accepted = true;
            }
          }
          converged = std::abs(f1) < 1e-13 * std::max(1.0, std::abs(l)) && std::abs(f2) < 1e-12;
          if (!accepted) break;
        }
        if (!converged || b < b_lo || b > b_hi) continue;
        const bool seen = std::any_of(found.begin(), found.end(),
                                      [&](const Root& r) { return std::abs(r.b - b) < 1e-8 * b; });
        if (!seen) found.push_back({g, b});
      }
    std::vector<HbPoint> library;
    for (const HbPoint& p : hb.solutions(l))
      if (p.amplitude > b_lo && p.amplitude < b_hi) library.push_back(p);
    for (const Root& r : found) {
      const auto match = std::find_if(library.begin(), library.end(), [&](const HbPoint& p) {
        return std::abs(p.amplitude - r.b) < 1e-9 * r.b && std::abs(p.offset + l - r.g) < 1e-11;
      });
      EXPECT_TRUE(match != library.end()) << "l=" << l << ": scan root B=" << r.b << " g=" << r.g
                                          << " not among the library's solutions";
      if (match != library.end()) {
        EXPECT_LE(residual(model, *match), 1e-10);
      }
    }
    EXPECT_EQ(found.size(), library.size()) << "l=" << l;
    std::printf("[ general HB ] DMT l=%-5g library %zu solution(s), dense scan + Newton %zu\n", l, library.size(),
                found.size());
  }
}

TEST(GeneralHarmonicBalance, DmtFoldsAreExtremaOfTheSeparation) {
  const TappingModel model = dmt_model();
  const HarmonicBalance& hb = dmt_balance();
  ASSERT_GE(hb.folds().size(), 2u);
  for (const HbFold& fold : hb.folds()) {
    const HbPoint& f = fold.point;
    EXPECT_LE(residual(model, f), 1e-10);
    // l along the curve near the fold as a function of B: the points of many rays q* + k·h near the fold point
    // (B is a regular parameter there even where q turns as well), a least-squares cubic l(B) whose stationary
    // point must be the fold
    const double h = 2e-7 * std::max(1.0, std::abs(f.q));
    std::vector<std::array<double, 2>> near;  // (B − B*)/B*, l − l*
    for (int k = -40; k <= 40; ++k)
      for (const HbPoint& p : hb.points_at_q(f.q + k * h))
        if (std::abs(p.amplitude - f.amplitude) < 2e-3 * f.amplitude)
          near.push_back({(p.amplitude - f.amplitude) / f.amplitude, p.separation - f.separation});
    ASSERT_GE(near.size(), 8u) << "fold q=" << f.q;
    Eigen::MatrixXd v(near.size(), 4);
    Eigen::VectorXd y(near.size());
    for (std::size_t k = 0; k < near.size(); ++k) {
      const double x = near[k][0] / 2e-3;
      v.row(static_cast<Eigen::Index>(k)) << 1.0, x, x * x, x * x * x;
      y[static_cast<Eigen::Index>(k)] = near[k][1];
    }
    const Eigen::Vector4d c = v.colPivHouseholderQr().solve(y);
    // root of c1 + 2 c2 x + 3 c3 x² nearest 0 (stable form)
    const double qa = 3 * c[3], qb = 2 * c[2], qc = c[1];
    const double disc = std::sqrt(std::max(0.0, qb * qb - 4 * qa * qc));
    const double vertex = 2e-3 * (std::abs(qa) < 1e-300 ? -qc / qb : qc / (-0.5 * (qb + std::copysign(disc, qb))));
    EXPECT_NEAR(vertex, 0.0, 1e-7) << "fold q=" << f.q;  // relative to B*
    EXPECT_EQ(c[2] < 0.0, fold.separation_maximum) << "fold q=" << f.q;
    for (const auto& [x, l] : near) {
      if (fold.separation_maximum) {
        EXPECT_LE(l, 1e-13) << "fold q=" << f.q;
      }
      if (!fold.separation_maximum) {
        EXPECT_GE(l, -1e-13) << "fold q=" << f.q;
      }
    }
    // two solutions appear / disappear across l_fold
    const double eps = 1e-6 * std::max(1.0, std::abs(f.separation));
    const int below = static_cast<int>(hb.solutions(f.separation - eps).size());
    const int above = static_cast<int>(hb.solutions(f.separation + eps).size());
    EXPECT_EQ(std::abs(above - below), 2) << "fold q=" << f.q << " l=" << f.separation;
    if (fold.separation_maximum) {
      EXPECT_GT(below, above);
    }
    std::printf("[ general HB ] DMT fold q=%.10f l=%.10f B=%.6f (%s): vertex of l(B) from %zu curve points at "
                "ΔB/B = %.1e\n", f.q, f.separation, f.amplitude, fold.separation_maximum ? "max" : "min", near.size(),
                vertex);
  }
}

TEST(GeneralHarmonicBalance, DmtLabelsFollowTheSlopeOnTheRay) {
  const TappingModel model = dmt_model();
  const HarmonicBalance& hb = dmt_balance();
  const std::complex<double> inverse = 1.0 / model.cantilever.transfer({0.0, model.drive.frequency});
  for (const double l : {9.0, 8.0, 5.0, 2.0}) {
    for (const HbPoint& p : hb.solutions(l)) {
      // ∂F/∂B at fixed q with the independent tanh_sinh describing functions
      auto f = [&](double b) {
        const auto d = test::tanh_sinh_df(model.law, p.q * b, b, model.drive.frequency);
        return std::abs(b * (inverse + d.first)) - model.drive.amplitude;
      };
      const double db = 1e-5 * p.amplitude;
      const double slope = f(p.amplitude + db) - f(p.amplitude - db);
      EXPECT_EQ(p.branch == HbBranch::Minus, slope < 0.0) << "l=" << l << " B=" << p.amplitude;
    }
  }
}

TEST(GeneralHarmonicBalance, CurveAndPointsAtQ) {
  const TappingModel model = dmt_model();
  const HarmonicBalance& hb = dmt_balance();
  HbCurveOptions o;
  o.points = 200;
  const std::vector<HbPoint> curve = harmonic_balance_curve(model, o);
  ASSERT_GT(curve.size(), 200u);
  std::size_t minus_start = 0;
  while (minus_start < curve.size() && curve[minus_start].branch != HbBranch::Minus) ++minus_start;
  for (std::size_t k = 0; k < curve.size(); ++k) {
    const HbPoint& p = curve[k];
    EXPECT_EQ(p.branch == HbBranch::Minus, k >= minus_start);
    if (k > 0 && k != minus_start) {
      EXPECT_GE(p.q, curve[k - 1].q);
    }
    if (k % 7 == 0) {
      EXPECT_LE(residual(model, p), 1e-10) << "q=" << p.q;
    }
  }
  // the points at one q are the curve's points at that q; at_q picks the largest amplitude of its branch
  for (const double q : {0.95, 0.99, 1.01, 1.1, -0.5}) {
    const std::vector<HbPoint> at = hb.points_at_q(q);
    for (const HbPoint& p : at) {
      EXPECT_NEAR(p.q, q, 1e-12 * std::max(1.0, std::abs(q)));
      EXPECT_LE(residual(model, p), 1e-10);
    }
    const auto plus = hb.at_q(q, HbBranch::Plus);
    double best = 0;
    for (const HbPoint& p : at)
      if (p.branch != HbBranch::Minus) best = std::max(best, p.amplitude);
    if (best > 0) {
      ASSERT_TRUE(plus.has_value());
      EXPECT_EQ(plus->amplitude, best);
    } else {
      EXPECT_FALSE(plus.has_value());
    }
    const auto one = harmonic_balance_at_q(model, q, HbBranch::Plus);
    EXPECT_EQ(one.has_value(), plus.has_value());
    if (one && plus) {
      EXPECT_NEAR(one->amplitude, plus->amplitude, 1e-12 * plus->amplitude);
    }
  }
  EXPECT_THROW(hb.points_at_q(std::nan("")), InvalidParameter);
}

TEST(GeneralHarmonicBalance, OtherLawsSolutionsSatisfyTheBalanceEquations) {
  struct Case {
    const char* name;
    impact::ForceLaw law;
    double ratio;
  };
  const Case cases[] = {
      {"dmt hysteresis", impact::DmtLaw(1.0, 0.8, 10.0, 6.4e-20, 1.0e-19, 0.165), 1.0},
      {"dmt below resonance", impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165), 0.998},
      {"jkr", impact::make_law<impact::AdhesionHysteresisLaw>(1.0, 10.0, 6.4e-20, 0.165, 0.05, 0.5), 1.0},
      {"kelvin-voigt", impact::make_law<impact::KelvinVoigtLaw>(1.0, 10.0, 6.4e-20, 0.165, 200.0), 1.0},
      {"lennard-jones", impact::make_law<impact::LennardJonesLaw>(10.0, 6.4e-20, 0.165), 1.0},
      {"hertz", impact::make_law<impact::HertzLaw>(1.0, 0.7, 10.0), 1.0}};
  for (const Case& c : cases) {
    const TappingModel model = physical(c.law, c.ratio);
    const HarmonicBalance hb(model);
    int n = 0;
    double worst = 0;
    for (const double l : {9.0, 7.0, 4.0, 1.0, 0.1}) {
      for (const HbPoint& p : hb.solutions(l)) {
        const double r = residual(model, p);
        EXPECT_LE(r, 1e-10) << c.name << " l=" << l << " B=" << p.amplitude;
        worst = std::max(worst, r);
        ++n;
      }
    }
    // (a hysteretic law may have no solution with B > 0 close to the sample: the branch difference acts as dry
    // friction, B·N1 → 2(H_a − H_b)/π as B → 0, and the curve ends at B → 0 — e.g. DMT with A_H,b > A_H,a)
    EXPECT_GE(n, 4) << c.name;
    const std::vector<HbPoint> far = hb.solutions(1000.0);  // van der Waals is long-ranged: far means far
    ASSERT_EQ(far.size(), 1u) << c.name;
    EXPECT_EQ(far[0].branch, HbBranch::Free) << c.name;
    EXPECT_NEAR(far[0].amplitude, hb.free_amplitude(), 1e-6 * hb.free_amplitude()) << c.name;
    for (const HbFold& f : hb.folds()) EXPECT_LE(residual(model, f.point), 1e-10) << c.name << " fold q=" << f.point.q;
    std::printf("[ general HB ] %-19s %d solutions, %zu folds, worst balance residual %.2e\n", c.name, n,
                hb.folds().size(), worst);
  }
}

// The general algorithm on a piecewise-linear law (wrapped in a CustomLaw: no closed form) against the closed form.
TEST(GeneralHarmonicBalance, ReproducesTheClosedFormOnPiecewiseLinearLaws) {
  struct Case {
    double w;
    PiecewiseLinearLaw law;
  };
  const Case cases[] = {{0.995, PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6)},
                        {0.99, PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.5, 1.0)},
                        {1.005, PiecewiseLinearLaw::linear_hysteresis(10, 6.4)},
                        {1.01, PiecewiseLinearLaw::repulsive_attractive(1000, 640, 0.3, 0.6)},
                        {1.0, PiecewiseLinearLaw::linear_repulsive(3.0)}};
  for (const Case& c : cases) {
    const PiecewiseLinearLaw law = c.law;
    const impact::ForceLaw custom(impact::CustomLaw{[law](double d) { return law.approach(d); },
                                                    [law](double d) { return law.departure(d); }, {0.0}, "pwl"});
    const TappingModel closed_model(Cantilever(1.0, 100.0), Drive(0.2, c.w), law, 0.0);
    const TappingModel general_model(Cantilever(1.0, 100.0), Drive(0.2, c.w), custom, 0.0);
    const HarmonicBalance closed(closed_model), general(general_model);
    ASSERT_TRUE(closed.closed_form());
    ASSERT_FALSE(general.closed_form());
    // folds
    ASSERT_EQ(general.folds().size(), closed.folds().size()) << "w=" << c.w;
    double worst_fold = 0;
    for (std::size_t k = 0; k < closed.folds().size(); ++k) {
      const HbPoint& a = closed.folds()[k].point;
      const HbPoint& b = general.folds()[k].point;
      EXPECT_NEAR(b.q, a.q, 1e-9 * std::max(1.0, std::abs(a.q))) << "w=" << c.w;
      EXPECT_NEAR(b.separation, a.separation, 1e-9 * std::max(1.0, std::abs(a.separation))) << "w=" << c.w;
      EXPECT_NEAR(b.amplitude, a.amplitude, 1e-9 * a.amplitude) << "w=" << c.w;
      EXPECT_EQ(b.branch, a.branch) << "w=" << c.w << " fold q=" << a.q;
      EXPECT_EQ(general.folds()[k].separation_maximum, closed.folds()[k].separation_maximum);
      worst_fold = std::max(worst_fold, std::abs(b.q - a.q));
    }
    // solutions over a range of separations
    double worst = 0;
    int n = 0;
    for (int k = 0; k <= 120; ++k) {
      const double l = -2.0 + 25.0 * k / 120 + 0.00123;
      const std::vector<HbPoint> a = closed.solutions(l), b = general.solutions(l);
      ASSERT_EQ(b.size(), a.size()) << "w=" << c.w << " l=" << l;
      for (std::size_t i = 0; i < a.size(); ++i) {
        const double e = std::abs(b[i].amplitude - a[i].amplitude) / a[i].amplitude +
                         std::abs(b[i].offset - a[i].offset) / a[i].amplitude +
                         std::abs(std::remainder(b[i].phase - a[i].phase, 2 * pi));
        EXPECT_LE(e, 1e-9) << "w=" << c.w << " l=" << l << " B=" << a[i].amplitude;
        EXPECT_EQ(b[i].branch, a[i].branch) << "w=" << c.w << " l=" << l << " B=" << a[i].amplitude;
        worst = std::max(worst, e);
        ++n;
      }
    }
    // the curve at the same samples: the same points (the general curve may hold more B → 0 end points: none here)
    HbCurveOptions o;
    o.points = 120;
    o.q_min = -1.5;
    o.q_max = 1.2;
    const std::vector<HbPoint> cc = harmonic_balance_curve(closed_model, o), gc = harmonic_balance_curve(general_model, o);
    int matched = 0;
    for (const HbPoint& p : cc) {
      const bool found = std::any_of(gc.begin(), gc.end(), [&](const HbPoint& g) {
        // (the closed form reports q = 1 − (1 − q): equal to the sample up to rounding)
        return std::abs(g.q - p.q) <= 1e-15 * std::max(1.0, std::abs(p.q)) && g.branch == p.branch &&
               std::abs(g.amplitude - p.amplitude) <= 1e-9 * p.amplitude;
      });
      EXPECT_TRUE(found) << "w=" << c.w << " q=" << p.q << " B=" << p.amplitude << " " << branch_name(p.branch);
      matched += found;
    }
    EXPECT_EQ(gc.size(), cc.size()) << "w=" << c.w;
    std::printf("[ general HB ] closed form w=%-5g: %d solutions (worst %.1e), %zu folds (worst |Δq| %.1e), "
                "%d/%zu curve points\n", c.w, n, worst, closed.folds().size(), worst_fold, matched, cc.size());
  }
}

// issue 24 §3: the first trace of the curve (thousands of describing-function evaluations, seconds for a finely
// tabulated law) checks the cancellation, so Ctrl-C in Python stops it.
TEST(GeneralHarmonicBalance, TheConstructionStopsOnRequest) {
  afmkit_test::CountingStop stop(3);
  EXPECT_THROW(HarmonicBalance(dmt_model(), stop.cancellation()), Cancelled);
  EXPECT_EQ(stop.calls.load(), 3);  // one check per 64 evaluations: stopped at the third
  const HarmonicBalance never(dmt_model(), Cancellation{});  // an empty cancellation never stops
  EXPECT_FALSE(never.folds().empty());
}

}  // namespace
}  // namespace afmkit::tapping
