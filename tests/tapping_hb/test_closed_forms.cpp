// Closed forms (18) and E1–E5 against the balance equations (17) with quadrature describing functions,
// a direct Newton solve of (17), the printed repulsive formulas, and a time-domain simulation (phase convention).
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

TappingModel make(double w, const PiecewiseLinearLaw& law, double l = 0.0) {
  return TappingModel(Cantilever(1.0, 100.0), Drive(0.2, w), law, l);
}

TEST(ClosedForms, SatisfyBalanceWithQuadratureDescribingFunctions) {
  double worst = 0;
  int points = 0;
  for (double w : {1.0, 0.995, 1.002}) {
    for (const auto& law : {PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.1, 0.3),
                            PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.5, 1.0),
                            PiecewiseLinearLaw::repulsive_attractive(100, 64, 0.3, 0.6),
                            PiecewiseLinearLaw::linear_hysteresis(10, 8)}) {
      const TappingModel model = make(w, law);
      std::vector<double> qs;
      for (int k = 0; k < 30; ++k) qs.push_back(-2.5 + 3.45 * k / 29.0);
      for (int k = 0; k < 8; ++k) qs.push_back(1.0 - std::pow(10.0, -2.0 - 4.0 * k / 7.0));
      qs.push_back(1.5);
      for (double q : qs) {
        for (HbBranch branch : {HbBranch::Plus, HbBranch::Minus}) {
          const auto p = harmonic_balance_at_q(model, q, branch);
          if (!p) continue;
          EXPECT_GT(p->amplitude, 0.0);
          EXPECT_NEAR((p->offset + p->separation) / p->amplitude, q, 1e-13 * std::max(1.0, std::abs(q)));
          const auto r = test::balance_residual(model.with_separation(p->separation), p->offset, p->amplitude,
                                                p->phase);
          for (double v : r) worst = std::max(worst, std::abs(v));
          ++points;
        }
      }
    }
  }
  EXPECT_GT(points, 400);
  EXPECT_LT(worst, 1e-11);
  std::printf("[ closed form ] (17) residual with quadrature DFs at %d branch points: max %.2e\n", points, worst);
}

TEST(ClosedForms, NewtonSolveOfBalanceConvergesToClosedForm) {
  double worst = 0;
  int solved = 0;
  for (double w : {1.0, 0.997}) {
    for (const auto& law : {PiecewiseLinearLaw::linear_hysteresis(10, 8), PiecewiseLinearLaw::linear_hysteresis(100, 64),
                            PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6)}) {
      const TappingModel model = make(w, law);
      for (double q : {0.99, 0.9, 0.5, 0.0, -0.5, -0.95, -1.5, -4.0}) {
        const auto p = harmonic_balance_at_q(model, q, HbBranch::Plus);
        ASSERT_TRUE(p.has_value());
        // start perturbed by ~0.2 % of B in each unknown (q moves by ~0.004: the start stays on the same side of q = ±1)
        const auto s = test::newton_solve(model.with_separation(p->separation), p->offset + 2e-3 * p->amplitude,
                                          p->amplitude * 0.997, p->phase + 0.003);
        ASSERT_TRUE(s.has_value()) << "q=" << q;
        const double dev = std::max({std::abs(s->offset - p->offset), std::abs(s->amplitude - p->amplitude),
                                     std::abs(std::remainder(s->phase - p->phase, 2 * pi))}) /
                           std::max(1.0, p->amplitude);
        worst = std::max(worst, dev);
        ++solved;
      }
    }
  }
  EXPECT_EQ(solved, 48);
  EXPECT_LT(worst, 1e-10);
  std::printf("[ closed form ] Newton solve of (17) vs closed form, %d cases: max deviation %.2e\n", solved, worst);
}

TEST(ClosedForms, RepulsiveMatchesPrintedEquation18) {
  // Eq. (18) as printed (with L(iω) for L(iωt), atan2), written out independently of the library.
  for (double w : {1.0, 0.99, 1.01}) {
    const double ka = 10, kb = 8, gamma = 0.2, xi = 0.005, wn = 1.0, l0 = 1.0;
    const TappingModel model = make(w, PiecewiseLinearLaw::linear_hysteresis(ka, kb));
    const std::complex<double> inverse(wn * wn - w * w, 2 * xi * wn * w);
    for (double q : {2.0, 1.0, 0.999, 0.7, 0.0, -0.7, -1.0, -3.0}) {
      std::complex<double> n1 = 0;
      if (q < 1 && q > -1)
        n1 = {-(ka + kb) / (2 * pi) * (q * std::sqrt(1 - q * q) - std::acos(q)), (ka - kb) / (2 * pi) * (1 - q) * (1 - q)};
      else if (q <= -1)
        n1 = {(ka + kb) / 2, -2 * (ka - kb) / pi * q};
      const std::complex<double> m = inverse + n1;
      const double b = gamma / std::abs(m);
      double a, l;
      if (q >= 1) {
        a = 0;
        l = q * gamma / std::abs(inverse);
      } else if (q > -1) {
        const double g = std::sqrt(1 - q * q) - q * std::acos(q);
        a = gamma * l0 * (ka + kb) / (2 * pi) * g / std::abs(m);
        l = (q - l0 * (ka + kb) / (2 * pi) * g) * gamma / std::abs(m);
      } else {
        a = -gamma * l0 * (ka + kb) / 2 * q / std::abs(m);
        l = (1 + l0 * (ka + kb) / 2) * q * gamma / std::abs(m);
      }
      const double phase = std::atan2(m.imag(), m.real());
      const auto p = harmonic_balance_at_q(model, q, HbBranch::Plus);
      ASSERT_TRUE(p.has_value());
      EXPECT_EQ(p->branch, q >= 1 ? HbBranch::Free : HbBranch::Plus);
      EXPECT_NEAR(p->amplitude, b, 1e-13 * b);
      EXPECT_NEAR(p->offset, a, 1e-9 * std::abs(a) + 1e-15);  // the printed form cancels near q = 1
      EXPECT_NEAR(p->separation, l, 1e-13 * std::max(1.0, std::abs(l)));
      EXPECT_NEAR(p->phase, phase, 1e-13);
      EXPECT_FALSE(harmonic_balance_at_q(model, q, HbBranch::Minus).has_value());  // B₋ < 0 when F = 0
    }
  }
}

// x ≈ A + B cos(ωt − φ) for the drive Γ cos ωt: check against a direct RK4 simulation of eq. (8).
TEST(ClosedForms, PhaseConventionAgainstTimeDomainSimulation) {
  const TappingModel model =
      TappingModel(Cantilever(1.0, 100.0), Drive(0.2, 1.0), PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), 10.0);
  const auto sols = harmonic_balance_solutions(model);
  ASSERT_EQ(sols.size(), 1u);
  const HbPoint hb = sols.front();
  const double w = model.drive.frequency, gamma = model.drive.amplitude;
  const double xi = model.cantilever.damping_ratio(), wn = model.cantilever.natural_frequency;
  auto rhs = [&](double t, double x, double v) {
    return gamma * std::cos(w * t) - 2 * xi * wn * v - wn * wn * x - model.interaction(x, v);
  };
  const int per_period = 800;
  const double dt = model.period() / per_period;
  double t = 0, x = hb.offset + hb.amplitude * std::cos(hb.phase), v = hb.amplitude * w * std::sin(hb.phase);
  const int settle = 400, measure = 20;
  double mean = 0, c = 0, s = 0;
  for (int k = 0; k < (settle + measure) * per_period; ++k) {
    if (k >= settle * per_period) {  // rectangle rule over whole periods (spectrally accurate for periodic x)
      mean += x;
      c += x * std::cos(w * t);
      s += x * std::sin(w * t);
    }
    const double k1x = v, k1v = rhs(t, x, v);
    const double k2x = v + 0.5 * dt * k1v, k2v = rhs(t + 0.5 * dt, x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
    const double k3x = v + 0.5 * dt * k2v, k3v = rhs(t + 0.5 * dt, x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
    const double k4x = v + dt * k3v, k4v = rhs(t + dt, x + dt * k3x, v + dt * k3v);
    x += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    t += dt;
  }
  const double n = measure * per_period;
  mean /= n;
  const double amp_c = 2 * c / n, amp_s = 2 * s / n;  // x ≈ A + B cos φ cos ωt + B sin φ sin ωt
  const double amplitude = std::hypot(amp_c, amp_s), phase = std::atan2(amp_s, amp_c);
  // HB is a one-harmonic approximation: docs/theory-tapping.md#hb-accuracy reports B within 1–2 %, A within 0.3 %, φ
  // within 0.005.
  EXPECT_NEAR(amplitude / hb.amplitude, 1.0, 0.02);
  EXPECT_NEAR(mean, hb.offset, 0.01 * std::abs(hb.offset));
  EXPECT_NEAR(phase, hb.phase, 0.01);
  std::printf("[ time domain ] HB A=%.5f B=%.4f phi=%.4f | RK4 A=%.5f B=%.4f phi=%.4f\n", hb.offset, hb.amplitude,
              hb.phase, mean, amplitude, phase);
}

TEST(ClosedForms, AtQBranchRulesAndBadInput) {
  const TappingModel model = make(1.0, PiecewiseLinearLaw::repulsive_attractive(10, 8, 0.3, 0.6), 3.0);
  const auto free = harmonic_balance_at_q(model, 1.2, HbBranch::Plus);
  ASSERT_TRUE(free.has_value());
  EXPECT_EQ(free->branch, HbBranch::Free);
  EXPECT_DOUBLE_EQ(free->amplitude, model.free_amplitude());
  EXPECT_DOUBLE_EQ(free->separation, 1.2 * model.free_amplitude());
  EXPECT_NEAR(free->phase, -std::arg(model.cantilever.transfer({0, 1.0})), 1e-15);
  EXPECT_FALSE(harmonic_balance_at_q(model, 1.2, HbBranch::Minus).has_value());
  EXPECT_FALSE(harmonic_balance_at_q(model, 0.5, HbBranch::Free).has_value());
  EXPECT_THROW(harmonic_balance_at_q(model, std::nan(""), HbBranch::Plus), InvalidParameter);
  // other laws: the general algorithm (test_general_hb.cpp); q is validated the same way
  const TappingModel dmt(Cantilever(1.0, 100.0), Drive(0.2, 1.0),
                         impact::ForceLaw(impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165)), 3.0);
  EXPECT_THROW(harmonic_balance_at_q(dmt, std::nan(""), HbBranch::Plus), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
