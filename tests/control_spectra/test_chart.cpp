// Stability charts: grid abscissa vs independent spectra, certified region labels, D-subdivision boundaries
// (Δ(iν) = 0 on them, spectral abscissa ≈ 0 where they border the stable region, and every sign change of the
// grid abscissa is crossed by a boundary curve), thread independence, delay-margin map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/control/stability_chart.hpp"
#include "afmkit/core/error.hpp"
#include "reference.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit;
using namespace afmkit::control;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kGamma;
using afmkit_test::fig5::kT;

ChartSpec fig2(int n, double tau) {
  ChartSpec s;
  s.family = LoopFamily::from_loop(LoopSpec(OscillatorBank::single(kOmega, 0.5, 0.0, kGamma), PlantKind::Static, kGamma, tau));
  s.x_min = -0.5;
  s.x_max = 2.0;
  s.y_min = -2.0;
  s.y_max = 1.5;
  s.x_points = s.y_points = n;
  return s;
}

ChartSpec fig4(int n, double tau) {
  ChartSpec s;
  s.family = LoopFamily::from_loop(LoopSpec(InfiniteBank(kOmega, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, tau));
  s.x_min = -0.1;
  s.x_max = 1.0;
  s.y_min = -0.4;
  s.y_max = 1.0;
  s.x_points = s.y_points = n;
  return s;
}

double segment_distance(double px, double py, const BoundaryPoint& a, const BoundaryPoint& b, double sx, double sy) {
  const double ax = (a.x - px) / sx, ay = (a.y - py) / sy, bx = (b.x - px) / sx, by = (b.y - py) / sy;
  const double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
  const double t = l2 > 0 ? std::clamp(-(ax * dx + ay * dy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(ax + t * dx, ay + t * dy);
}

// Every pair of neighbouring grid points with abscissae of opposite sign has a boundary curve between them.
void expect_sign_changes_on_boundaries(const StabilityChart& c) {
  const int nx = static_cast<int>(c.x.size()), ny = static_cast<int>(c.y.size());
  const double hx = c.x[1] - c.x[0], hy = c.y[1] - c.y[0];
  int changes = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      for (auto [di, dj] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (i + di >= nx || j + dj >= ny) continue;
        const double a = c.at(i, j), b = c.at(i + di, j + dj);
        if ((a < 0) == (b < 0)) continue;
        ++changes;
        const double mx = 0.5 * (c.x[i] + c.x[i + di]), my = 0.5 * (c.y[j] + c.y[j + dj]);
        double best = INFINITY;
        for (const auto& curve : c.boundaries)
          for (std::size_t k = 0; k + 1 < curve.size(); ++k)
            best = std::min(best, segment_distance(mx, my, curve[k], curve[k + 1], hx, hy));
        EXPECT_LT(best, 0.75) << "sign change at (" << mx << ", " << my << ") without a boundary curve";
      }
  EXPECT_GT(changes, 0);
}
}  // namespace

TEST(StabilityChart, Fig2GridMatchesIndependentCollocation) {
  const double tau = 0.1 * kT;
  ChartSpec s = fig2(31, tau);
  s.threads = 2;
  const StabilityChart c = stability_chart(s);
  EXPECT_EQ(c.mismatched_points, 0);
  for (int k = 0; k < 12; ++k) {
    const int i = (7 * k + 3) % 31, j = (11 * k + 5) % 31;
    double ref = -INFINITY;
    for (auto e : test::reference_roots(OscillatorBank::single(kOmega, c.x[i], c.y[j], kGamma), PlantKind::Static, kGamma, tau, 48))
      ref = std::max(ref, e.real());
    EXPECT_NEAR(c.at(i, j), ref, 1e-7) << c.x[i] << " " << c.y[j];
  }
  // regions: stable one (0 unstable roots), the real root above b = γΩ/K (1), and a complex pair (2)
  bool stable = false, real_root = false;
  for (const auto& r : c.regions) {
    EXPECT_TRUE(r.certified);
    if (r.unstable_roots == 0) stable = true;
    if (r.unstable_roots == 1) {
      real_root = true;
      EXPECT_GT(r.y, 1.0);  // above the line b = γΩ/K
    }
  }
  EXPECT_TRUE(stable);
  EXPECT_TRUE(real_root);
  expect_sign_changes_on_boundaries(c);
  // the s = 0 line is b = γΩ/K = 1 for every τ (the thick horizontal line of Fig. 2)
  bool line = false;
  for (const auto& curve : c.boundaries)
    if (curve.front().frequency == 0.0) {
      line = true;
      for (const auto& q : curve) EXPECT_NEAR(q.y, kGamma * kOmega / kGamma, 1e-12);
    }
  EXPECT_TRUE(line);
}

TEST(StabilityChart, BoundaryPointsAreCrossings) {
  const double tau = 0.2 * kT;
  const LoopFamily f = fig2(3, tau).family;
  const auto curves = stability_boundaries(f, -0.5, 2.0, -2.0, 1.5);
  ASSERT_FALSE(curves.empty());
  int on_border = 0;
  for (const auto& curve : curves) {
    for (std::size_t k = 1; k + 1 < curve.size(); k += std::max<std::size_t>(1, curve.size() / 6)) {
      const BoundaryPoint& q = curve[k];
      if (q.frequency == 0.0 || q.x < -0.5 || q.x > 2.0 || q.y < -2.0 || q.y > 1.5) continue;
      const LoopSpec loop = f.at(q.x, q.y);
      // a root at iν: |Δ(iν)| ≪ |Δ'(iν)|·ν
      const std::complex<double> s(0.0, q.frequency);
      EXPECT_LT(std::abs(characteristic(loop, s)), 1e-9 * std::abs(characteristic_derivative(loop, s)) * (1.0 + q.frequency));
      const Spectrum sp = rightmost_roots(loop);
      EXPECT_GT(sp.spectral_abscissa, -1e-9);
      // where one side of the curve is stable the abscissa on the curve is 0
      const double nx = -(curve[k + 1].y - curve[k - 1].y), ny = curve[k + 1].x - curve[k - 1].x;
      const double nn = std::hypot(nx, ny), e = 1e-3;
      const double s1 = rightmost_roots(f.at(q.x + e * nx / nn, q.y + e * ny / nn)).spectral_abscissa;
      const double s2 = rightmost_roots(f.at(q.x - e * nx / nn, q.y - e * ny / nn)).spectral_abscissa;
      if (std::min(s1, s2) < 0.0) {
        ++on_border;
        EXPECT_NEAR(sp.spectral_abscissa, 0.0, 1e-9);
      }
    }
  }
  EXPECT_GT(on_border, 2);
}

TEST(StabilityChart, Fig4InfiniteBankRegionsAndThreads) {
  const double tau = 0.1 * kT;
  ChartSpec s = fig4(21, tau);
  s.threads = 1;
  const StabilityChart c1 = stability_chart(s);
  s.threads = 2;
  const StabilityChart c2 = stability_chart(s);
  EXPECT_EQ(c1.abscissa, c2.abscissa);
  EXPECT_EQ(c1.unstable_roots, c2.unstable_roots);
  EXPECT_EQ(c2.mismatched_points, 0);
  // α < 0 column: infinitely many unstable roots (neutral chain), abscissa = ln|B4/A4|/T > 0
  EXPECT_EQ(c2.unstable_roots[0], -1);
  EXPECT_GT(c2.at(0, 0), 0.0);
  // samples vs the certified spectrum (argument principle + subdivision)
  for (int k = 0; k < 8; ++k) {
    const int i = 1 + (5 * k + 2) % 20, j = (7 * k + 1) % 21;
    EXPECT_NEAR(c2.at(i, j), rightmost_roots(s.family.at(c2.x[i], c2.y[j])).spectral_abscissa, 1e-8)
        << c2.x[i] << " " << c2.y[j];
  }
  expect_sign_changes_on_boundaries(c2);
}

TEST(StabilityChart, MarginMapMatchesDelayMargin) {
  const LoopFamily f = fig4(3, 0.0).family;
  const MarginMap m = delay_margin_map(f, 0.05, 0.5, 4, -0.2, 0.3, 3, 2);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i) {
      const DelayMargin d = delay_margin(f.at(m.x[i], m.y[j]));
      const double v = m.critical_delay[j * 4 + i];
      if (d.stable_at_reference) {
        EXPECT_DOUBLE_EQ(v, d.upper);
      }
      else EXPECT_TRUE(std::isnan(v));
    }
}

TEST(LoopFamily, RoundTripsEveryControllerKind) {
  const double tau = 0.17 * kT;
  const std::vector<LoopSpec> loops{
      LoopSpec(OscillatorBank::single(kOmega, 0.3, -0.2, 15.0), PlantKind::Static, kGamma, tau),
      LoopSpec(OscillatorBank::with_couplings(kOmega, 6, 0.2, -0.1, 15.0, {1, 2}), PlantKind::FirstOrder, kGamma, tau),
      LoopSpec(InfiniteBank(kOmega, 0.2, -0.1, 15.0), PlantKind::Static, kGamma, tau),
      LoopSpec(SmithPredictor(OscillatorBank::with_couplings(kOmega, 4, 0.2, -0.1, 15.0), PlantKind::Static, 18.0, 0.2 * kT),
               PlantKind::Static, kGamma, tau)};
  const double xy[][2] = {{0.3, -0.2}, {0.2, -0.1}, {0.2, -0.1}, {0.2, -0.1}};
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const LoopFamily f = LoopFamily::from_loop(loops[i]);
    const LoopSpec back = f.at(xy[i][0], xy[i][1]);
    for (std::complex<double> s : {std::complex<double>(0.1, 0.7), std::complex<double>(-0.3, 2.2)})
      EXPECT_LT(std::abs(characteristic(back, s) - characteristic(loops[i], s)), 1e-13 * std::abs(characteristic(loops[i], s)))
          << f.describe();
    // ρ = K/γ changes the plant rate only
    const LoopSpec half = f.at(xy[i][0], xy[i][1], tau, 0.5);
    EXPECT_DOUBLE_EQ(half.gain_ratio(), 0.5);
    EXPECT_DOUBLE_EQ(half.gain(), loops[i].gain());
  }
}

TEST(StabilityChart, BadInput) {
  ChartSpec s = fig2(10, 0.1);
  s.x_points = 1;
  EXPECT_THROW(stability_chart(s), InvalidParameter);
  s = fig2(10, 0.1);
  s.y_max = s.y_min;
  try {
    stability_chart(s);
    ADD_FAILURE();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "y_max");
  }
  EXPECT_THROW(stability_boundaries(s.family, 0.0, 1.0, 0.0, std::nan("")), InvalidParameter);
  EXPECT_THROW(s.family.at(std::nan(""), 0.0), InvalidParameter);
}

// A large bank (N = 300 > the collocation limit) over a window that reaches α < 0, where nearly every root of the
// bank is unstable: the tracked counts there are lower bounds (lower_bound_points, not mismatches), and the grid
// abscissa equals the certified rightmost root of rightmost_roots() at points on both sides of α = 0 — including
// α > 0, where the rightmost stable roots sit at the top of the bank (k ≈ N), not at the low harmonics.
TEST(StabilityChart, LargeBankAbscissaAndLowerBoundCounts) {
  ChartSpec s;
  s.family = LoopFamily::from_loop(
      LoopSpec(OscillatorBank::with_couplings(kOmega, 300, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, 0.1 * kT));
  s.x_min = -0.1;
  s.x_max = 0.5;
  s.y_min = -0.2;
  s.y_max = 0.4;
  s.x_points = s.y_points = 7;
  s.boundaries = false;
  const StabilityChart c = stability_chart(s);
  EXPECT_GT(c.lower_bound_points, 0);
  EXPECT_EQ(c.recomputed_points, c.mismatched_points);  // a coarse grid: tracking loses roots, recomputed
  for (const auto& [ix, iy] : {std::pair{0, 0}, std::pair{0, 6}, std::pair{4, 3}, std::pair{6, 6}}) {
    const Spectrum sp = rightmost_roots(s.family.at(c.x[ix], c.y[iy]));
    EXPECT_NEAR(c.at(ix, iy), sp.spectral_abscissa, 1e-8) << "alpha " << c.x[ix] << " beta " << c.y[iy];
  }
}
