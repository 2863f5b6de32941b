// Numerical describing functions (numerical_describing_functions.hpp) against the closed forms of seed 1 for the
// piecewise-linear laws (≤ 1e-12 of the N1 scale, including grazing and permanent contact) and against an
// independent tanh_sinh quadrature for the non-linear laws (DMT + vdW, JKR-like with its jump, Kelvin–Voigt with
// its velocity term, Lennard-Jones, Hertz).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/contact_laws.hpp"
#include "afmkit/tapping/describing_functions.hpp"
#include "afmkit/tapping/numerical_describing_functions.hpp"
#include "reference.hpp"

namespace afmkit::tapping {
namespace {

using impact::PiecewiseLinearLaw;
using std::numbers::pi;

// The same law hidden behind a CustomLaw (piecewise_linear() is null: the numerical path).
impact::ForceLaw as_custom(const PiecewiseLinearLaw& law) {
  return impact::ForceLaw(impact::CustomLaw{[law](double d) { return law.approach(d); },
                                            [law](double d) { return law.departure(d); }, {0.0}, "pwl"});
}

// Physical laws in the normalised units of the tapping model (k = 40 N/m, f0 = 300 kHz).
impact::ForceLaw normalised_df(const impact::ForceLaw& law) { return law.scaled(1.0 / 40.0, 2.0 * pi * 3e5); }

TEST(NumericalDescribingFunctions, EqualClosedFormsForPiecewiseLinearLaws) {
  const PiecewiseLinearLaw laws[] = {PiecewiseLinearLaw::linear_repulsive(3.0),
                                     PiecewiseLinearLaw::linear_hysteresis(10.0, 8.0),
                                     PiecewiseLinearLaw::repulsive_attractive(2.0, 1.6, 0.1, 0.3),
                                     PiecewiseLinearLaw::repulsive_attractive(100.0, 64.0, 0.5, 1.0),
                                     PiecewiseLinearLaw::repulsive_attractive(1000.0, 640.0, 0.3, 0.6)};
  double worst = 0.0;
  int cases = 0;
  for (const auto& law : laws) {
    const DescribingFunctionQuadrature numeric(as_custom(law), 1.0);
    const DescribingFunctionQuadrature direct(impact::ForceLaw(law), 1.0);  // the quadrature on the PWL law itself
    // gaps s = 1 − q: every regime, grazing s → 0⁺ (to 1e-13), q → −1⁺ (to 1e-7: the closed form itself forms
    // 1 + q = 2 − s there), permanent contact (q down to −1000), no contact
    std::vector<double> gaps;
    for (int k = 0; k <= 120; ++k) gaps.push_back(1.0 - (-3.0 + 0.05 * k + 0.0123));
    for (int k = 1; k <= 13; ++k) gaps.push_back(std::pow(10.0, -k));
    for (int k = 1; k <= 7; ++k) gaps.push_back(2.0 - std::pow(10.0, -k));
    for (int k = 0; k <= 3; ++k) gaps.push_back(1.0 + std::pow(10.0, k));
    gaps.insert(gaps.end(), {0.0, 2.0, -0.5, -99.0});
    for (const double b : {0.05, 0.7, 3.0, 20.0}) {
      for (const double s : gaps) {
        // the mean gap handed to the quadrature, and the gap s it represents exactly (B − g is exact near
        // grazing), from which the closed form is evaluated — so both see the same orbit
        const double g = s < 0.5 ? b - s * b : b * (1.0 - s);
        const double gap = s < 0.5 ? (b - g) / b : 1.0 - g / b;
        const double q = 1.0 - gap;
        DescribingFunctions cf;
        if (gap > 0.0 && gap < 2.0) {
          const BarFunctions bar = bar_functions_from_gap(gap);
          cf = {(law.approach_adhesion + law.departure_adhesion) * bar.chi -
                    (law.approach_stiffness + law.departure_stiffness) * bar.omega * b,
                adhesion_term(law, bar) / b + stiffness_term(law, bar)};
        } else {
          cf = describing_functions(law, q, b);
        }
        // scale of N1 (and of the mean / B): Σ_K + Σ_F/B, or |N1| itself when larger (permanent contact)
        const double scale = std::max(law.approach_stiffness + law.departure_stiffness +
                                          (law.approach_adhesion + law.departure_adhesion) / b,
                                      std::abs(cf.first_harmonic));
        const double mean_scale = std::max(scale * b, std::abs(cf.mean));
        for (const DescribingFunctionQuadrature* quad : {&numeric, &direct}) {
          const DescribingFunctions nu = quad->at_gap(g, b);
          const double e1 = std::abs(nu.first_harmonic - cf.first_harmonic) / scale;
          const double e0 = std::abs(nu.mean - cf.mean) / mean_scale;
          EXPECT_LE(e1, 1e-12) << "1 − q=" << gap << " B=" << b << " K_a=" << law.approach_stiffness;
          EXPECT_LE(e0, 1e-12) << "1 − q=" << gap << " B=" << b << " K_a=" << law.approach_stiffness;
          worst = std::max({worst, e0, e1});
          ++cases;
        }
      }
    }
  }
  std::printf("[ numerical DF ] %d cases, worst |numerical − closed form| / scale = %.2e\n", cases, worst);
}

struct LawCase {
  const char* name;
  impact::ForceLaw law;
};

std::vector<LawCase> nonlinear_laws() {
  return {{"dmt", normalised_df(impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165))},
          {"dmt hysteresis", normalised_df(impact::DmtLaw(1.0, 0.8, 10.0, 6.4e-20, 1.0e-19, 0.165))},
          {"jkr", normalised_df(impact::make_law<impact::AdhesionHysteresisLaw>(1.0, 10.0, 6.4e-20, 0.165, 0.05, 0.5))},
          {"kelvin-voigt", normalised_df(impact::make_law<impact::KelvinVoigtLaw>(1.0, 10.0, 6.4e-20, 0.165, 200.0))},
          {"lennard-jones", normalised_df(impact::make_law<impact::LennardJonesLaw>(10.0, 6.4e-20, 0.165))},
          {"hertz", normalised_df(impact::make_law<impact::HertzLaw>(1.0, 0.7, 10.0))}};
}

TEST(NumericalDescribingFunctions, MatchIndependentTanhSinhQuadrature) {
  for (const LawCase& c : nonlinear_laws()) {
    const double omega = 1.0;
    const DescribingFunctionQuadrature quad(c.law, omega);
    double worst = 0.0;
    int n = 0;
    for (const double b : {0.3, 2.0, 9.5}) {
      for (int k = 0; k <= 40; ++k) {
        // mean gaps from permanent contact through every crossing of the switching gaps to far away
        const double g = -1.0 + (b + 2.5) * k / 40.0 + 0.00731;
        NumericalDfInfo info;
        const DescribingFunctions nu = quad.at_gap(g, b, &info);
        const test::QuadratureDf ref = test::tanh_sinh_df(c.law, g, b, omega);
        // the integrand scale, in the units of N1 and of the mean
        const double s1 = info.scale / (pi * b), s0 = info.scale / (2.0 * pi);
        if (info.scale == 0.0) {  // out of range of a finite-range law: both exactly zero
          EXPECT_EQ(std::abs(ref.first) + std::abs(ref.mean), 0.0) << c.name << " g=" << g << " B=" << b;
          EXPECT_EQ(std::abs(nu.first_harmonic) + std::abs(nu.mean), 0.0) << c.name << " g=" << g << " B=" << b;
          continue;
        }
        const double e = std::max(std::abs(nu.first_harmonic - ref.first) / s1, std::abs(nu.mean - ref.mean) / s0);
        EXPECT_LE(e, 1e-12) << c.name << " g=" << g << " B=" << b;
        EXPECT_TRUE(info.converged) << c.name << " g=" << g << " B=" << b;
        worst = std::max(worst, e);
        ++n;
      }
    }
    std::printf("[ numerical DF ] %-14s %d cases, worst |numerical − tanh_sinh| / integrand scale = %.2e\n", c.name,
                n, worst);
  }
}

TEST(NumericalDescribingFunctions, VelocityTermAndHysteresisGiveDissipation) {
  // Im N1 ≥ 0 for dissipative laws; the Kelvin–Voigt term adds exactly ∫ 2c(d)Bω sin²θ dθ/(πB), proportional to ω.
  const impact::ForceLaw kv = normalised_df(impact::make_law<impact::KelvinVoigtLaw>(1.0, 10.0, 6.4e-20, 0.165, 200.0));
  const impact::ForceLaw elastic = normalised_df(impact::make_law<impact::KelvinVoigtLaw>(1.0, 10.0, 6.4e-20, 0.165, 0.0));
  for (const double g : {1.0, 2.5}) {
    const double b = 3.0;
    const auto w1 = DescribingFunctionQuadrature(kv, 1.0).at_gap(g, b);
    const auto w2 = DescribingFunctionQuadrature(kv, 2.0).at_gap(g, b);
    const auto e = DescribingFunctionQuadrature(elastic, 1.0).at_gap(g, b);
    EXPECT_GT(w1.first_harmonic.imag(), 0.0);
    EXPECT_NEAR(e.first_harmonic.imag(), 0.0, 1e-15);
    EXPECT_NEAR(w2.first_harmonic.imag(), 2.0 * w1.first_harmonic.imag(), 1e-13 * std::abs(w1.first_harmonic));
    EXPECT_NEAR(w1.first_harmonic.real(), e.first_harmonic.real(), 1e-14 * std::abs(e.first_harmonic));
    EXPECT_NEAR(w1.mean, e.mean, 1e-15 * std::abs(e.mean) + 1e-18);
  }
}

TEST(NumericalDescribingFunctions, DispatchAndBadInput) {
  const PiecewiseLinearLaw law = PiecewiseLinearLaw::repulsive_attractive(10.0, 8.0, 0.3, 0.6);
  // closed form for a piecewise-linear ForceLaw, numerical otherwise
  const impact::ForceLaw pwl(law);
  const DescribingFunctions a = describing_functions(pwl, 0.3, 2.0);
  const DescribingFunctions b = describing_functions(law, 0.3, 2.0);
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(a.first_harmonic, b.first_harmonic);
  EXPECT_EQ(describing_functions(pwl, 0.1, 2.0, 0.5, 3.0).first_harmonic, b.first_harmonic);
  const impact::ForceLaw dmt = normalised_df(impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165));
  const DescribingFunctions d = describing_functions(dmt, 0.3, 2.0);
  const DescribingFunctions n = numerical_describing_functions(dmt, 0.1, 2.0, 0.5, 1.0);
  EXPECT_EQ(d.first_harmonic, n.first_harmonic);
  EXPECT_EQ(d.mean, n.mean);
  const impact::ForceLaw kv = normalised_df(impact::make_law<impact::KelvinVoigtLaw>(1.0, 10.0, 6.4e-20, 0.165, 200.0));
  try {
    describing_functions(kv, 0.3, 2.0);
    FAIL() << "expected InvalidParameter";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "frequency");
  }
  EXPECT_NO_THROW(describing_functions(kv, 0.1, 2.0, 0.5, 1.0));
  const DescribingFunctionQuadrature quad(dmt, 1.0);
  EXPECT_THROW(quad.at_gap(std::nan(""), 1.0), InvalidParameter);
  EXPECT_THROW(quad.at_gap(1.0, 0.0), InvalidParameter);
  EXPECT_THROW(quad.at_gap(1.0, INFINITY), InvalidParameter);
  EXPECT_THROW(DescribingFunctionQuadrature(dmt, 0.0), InvalidParameter);
  NumericalDfOptions o;
  o.relative_tolerance = 0.0;
  EXPECT_THROW(DescribingFunctionQuadrature(dmt, 1.0, o), InvalidParameter);
  o = {};
  o.max_panels = 0;
  EXPECT_THROW(DescribingFunctionQuadrature(dmt, 1.0, o), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
