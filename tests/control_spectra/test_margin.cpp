// Delay margins: the numbers of docs/theory-control.md#delay-margin, E1 closed form vs E2 search, and every τ_c checked
// by the spectrum just below (0.97 τ_c: stable) and above (1.03 τ_c: unstable) — by the independent full-state
// collocation for finite banks and by the argument principle for N = ∞ and the Smith predictor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/core/error.hpp"
#include "reference.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit;
using namespace afmkit::control;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kGamma;
using afmkit_test::fig5::kT;

double reference_abscissa(const OscillatorBank& bank, PlantKind kind, double gamma, double tau) {
  double m = -INFINITY;
  for (auto e : test::reference_roots(bank, kind, gamma, tau, 40)) m = std::max(m, e.real());
  return m;
}
}  // namespace

TEST(DelayMargin, SingleOscillatorMathMdValues) {
  const double cases[][3] = {{0.1, 0.0, 0.238}, {0.5, 0.0, 0.195}, {0.1, 0.5, 0.375}, {1.0, -1.0, 0.096}};
  for (const auto& c : cases) {
    const LoopSpec loop(OscillatorBank::single(kOmega, c[0], c[1], kGamma), PlantKind::Static, kGamma, 0.0);
    const DelayMargin m = delay_margin(loop);
    ASSERT_TRUE(m.stable_at_reference);
    EXPECT_EQ(m.method, "E1");
    EXPECT_NEAR(m.upper / kT, c[2], 5e-4) << c[0] << " " << c[1];
  }
}

TEST(DelayMargin, InfiniteBankMathMdValues) {
  const double cases[][3] = {{0.05, -0.05, 0.337}, {0.1, -0.1, 0.294}, {0.1, 0.0, 0.215}, {0.2, -0.1, 0.202},
                             {0.3, 0.1, 0.121},    {0.5, 0.0, 0.089},   {1.0, 0.5, 0.047}};
  for (const auto& c : cases) {
    const LoopSpec loop(InfiniteBank(kOmega, c[0], c[1], kGamma), PlantKind::Static, kGamma, 0.0);
    const DelayMargin m = delay_margin(loop);
    ASSERT_TRUE(m.stable_at_reference);
    EXPECT_NEAR(m.upper / kT, c[2], 5e-4) << c[0] << " " << c[1];
    // just below: stable; just above: unstable (argument principle on Δ)
    EXPECT_EQ(unstable_roots(loop.with_delay(0.97 * m.upper)).count, 0);
    EXPECT_GT(unstable_roots(loop.with_delay(1.03 * m.upper)).count, 0);
  }
  // gain-estimate mismatch (docs/theory-control.md#delay-margin): ρ = 0.5 → 0.327 T, ρ = 2 → 0.239 T
  for (const auto& [rho, expected] : {std::pair{0.5, 0.327}, std::pair{2.0, 0.239}}) {
    const LoopSpec loop(InfiniteBank(kOmega, 0.1, -0.1, rho * kGamma), PlantKind::Static, kGamma, 0.0);
    EXPECT_NEAR(delay_margin(loop).upper / kT, expected, 5e-4);
  }
}

TEST(DelayMargin, ClosedFormE1EqualsGeneralSearchE2) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ua(0.05, 2.0), ub(-2.0, 0.95), uk(0.5, 2.0);
  MarginOptions general;
  general.use_closed_form = false;
  for (int i = 0; i < 20; ++i) {
    const double a = ua(rng), b = ub(rng), kappa = uk(rng);
    const LoopSpec loop(OscillatorBank::single(kOmega, a, b, kappa * kGamma), PlantKind::Static, kGamma, 0.0);
    const DelayMargin e1 = delay_margin(loop), e2 = delay_margin(loop, general);
    ASSERT_EQ(e1.stable_at_reference, e2.stable_at_reference);
    if (!e1.stable_at_reference) continue;
    EXPECT_EQ(e2.method, "E2");
    EXPECT_NEAR(e1.upper, e2.upper, 1e-9 * std::max(1.0, e1.upper)) << a << " " << b << " " << kappa;
    EXPECT_NEAR(e1.upper_frequency, e2.upper_frequency, 1e-9);
  }
}

TEST(DelayMargin, CriticalDelaysBracketTheSpectrumCrossing) {
  // finite banks: checked by the independent full-state collocation (analogues of the 40/40 and 25/25 checks of
  // docs/theory-control.md#delay-margin)
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ua(0.05, 2.0), ub(-2.0, 0.95), ual(0.02, 1.0), ube(-0.22, 1.0);
  int checked = 0;
  for (int i = 0; i < 8; ++i) {
    const auto bank = OscillatorBank::single(kOmega, ua(rng), ub(rng), kGamma);
    const DelayMargin m = delay_margin(LoopSpec(bank, PlantKind::Static, kGamma, 0.0));
    if (!m.stable_at_reference || !(m.upper < 1.5 * kT)) continue;
    EXPECT_LT(reference_abscissa(bank, PlantKind::Static, kGamma, 0.97 * m.upper), 0.0);
    EXPECT_GT(reference_abscissa(bank, PlantKind::Static, kGamma, 1.03 * m.upper), 0.0);
    ++checked;
  }
  for (int i = 0; i < 6; ++i) {
    const auto bank = OscillatorBank::with_couplings(kOmega, 3, ual(rng), ube(rng), kGamma);
    const DelayMargin m = delay_margin(LoopSpec(bank, PlantKind::Static, kGamma, 0.0));
    if (!m.stable_at_reference || !(m.upper < kT)) continue;
    EXPECT_LT(reference_abscissa(bank, PlantKind::Static, kGamma, 0.97 * m.upper), 0.0);
    EXPECT_GT(reference_abscissa(bank, PlantKind::Static, kGamma, 1.03 * m.upper), 0.0);
    ++checked;
  }
  // N = 10 (theory-control.md#delay-margin: 25/25 with an independent collocation): argument-principle counts on Δ
  for (int i = 0; i < 6; ++i) {
    const LoopSpec loop(OscillatorBank::with_couplings(kOmega, 10, ual(rng), ube(rng), kGamma), PlantKind::Static,
                        kGamma, 0.0);
    const DelayMargin m = delay_margin(loop);
    if (!m.stable_at_reference || !(m.upper < kT)) continue;
    EXPECT_EQ(unstable_roots(loop.with_delay(0.97 * m.upper)).count, 0);
    EXPECT_GT(unstable_roots(loop.with_delay(1.03 * m.upper)).count, 0);
    ++checked;
  }
  // other rejected harmonics and the first-order plant
  for (const auto& [rejected, kind] : {std::pair{std::vector<int>{1, 3}, PlantKind::Static},
                                       std::pair{std::vector<int>{1, 2}, PlantKind::FirstOrder},
                                       std::pair{std::vector<int>{1}, PlantKind::FirstOrder}}) {
    const auto bank = OscillatorBank::with_couplings(kOmega, 3, 0.1, -0.05, kGamma, rejected);
    const DelayMargin m = delay_margin(LoopSpec(bank, kind, kGamma, 0.0));
    ASSERT_TRUE(m.stable_at_reference);
    ASSERT_LT(m.upper, 2.0 * kT);
    EXPECT_LT(reference_abscissa(bank, kind, kGamma, 0.97 * m.upper), 0.0);
    EXPECT_GT(reference_abscissa(bank, kind, kGamma, 1.03 * m.upper), 0.0);
    ++checked;
  }
  EXPECT_GE(checked, 8);
}

TEST(DelayMargin, SmithPredictorStabilityInterval) {
  const double model_delay = 0.5 * kT;
  for (auto structure : {SmithPredictor::Structure::Periodic, SmithPredictor::Structure::Classic}) {
    const SmithPredictor sp(OscillatorBank::with_couplings(kOmega, 5, 0.1, -0.1, kGamma), PlantKind::Static, 0.8 * kGamma,
                            model_delay, structure);
    const LoopSpec loop(sp, PlantKind::Static, kGamma, model_delay);
    const DelayMargin m = delay_margin(loop);
    ASSERT_TRUE(m.stable_at_reference);
    EXPECT_EQ(m.reference_delay, model_delay);
    ASSERT_LT(m.lower, model_delay);
    ASSERT_GT(m.upper, model_delay);
    ASSERT_TRUE(std::isfinite(m.upper));
    EXPECT_EQ(unstable_roots(loop.with_delay(m.upper - 0.01 * (m.upper - m.lower))).count, 0);
    EXPECT_GT(unstable_roots(loop.with_delay(m.upper * 1.02)).count, 0);
    if (m.lower > 0.0) {
      EXPECT_EQ(unstable_roots(loop.with_delay(m.lower + 0.01 * (m.upper - m.lower))).count, 0);
      EXPECT_GT(unstable_roots(loop.with_delay(m.lower * 0.98)).count, 0);
    }
  }
}

TEST(DelayMargin, UnstableWithoutDelayIsReported) {
  const DelayMargin a = delay_margin(LoopSpec(InfiniteBank(kOmega, 0.1, -0.3, kGamma), PlantKind::Static, kGamma, 0.0));
  EXPECT_FALSE(a.stable_at_reference);  // β < −Ω/4 (eq. 24)
  EXPECT_TRUE(std::isnan(a.upper));
  EXPECT_FALSE(a.note.empty());
  const DelayMargin b = delay_margin(LoopSpec(InfiniteBank(kOmega, -0.1, 0.0, kGamma), PlantKind::Static, kGamma, 0.0));
  EXPECT_EQ(b.unstable_at_reference, -1);  // neutral chain in the right half-plane
  const DelayMargin c = delay_margin(LoopSpec(OscillatorBank::single(kOmega, -0.2, 0.0, kGamma), PlantKind::Static, kGamma, 0.0));
  EXPECT_FALSE(c.stable_at_reference);
  EXPECT_EQ(c.unstable_at_reference, 2);
}

TEST(DelayMargin, LargeMarginsAreFlagged) {
  // Smith predictor with an exact model of a delay longer than T: the stability interval lies beyond T (allowed,
  // flagged)
  const SmithPredictor sp(InfiniteBank(kOmega, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, 1.2 * kT);
  const DelayMargin m = delay_margin(LoopSpec(sp, PlantKind::Static, kGamma, 1.2 * kT));
  ASSERT_TRUE(m.stable_at_reference);
  EXPECT_GT(m.upper, 1.2 * kT);
  EXPECT_TRUE(m.upper_exceeds_period);
  EXPECT_LT(m.lower, 1.2 * kT);
}

TEST(DelayMargin, BadInput) {
  const LoopSpec loop(OscillatorBank::single(kOmega, 0.5, 0.0, kGamma), PlantKind::Static, kGamma, 0.0);
  MarginOptions o;
  o.reference_delay = -1.0;
  try {
    delay_margin(loop, o);
    ADD_FAILURE();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "reference_delay");
  }
  o = MarginOptions{};
  o.grid_points_per_omega = 1;
  EXPECT_THROW(delay_margin(loop, o), InvalidParameter);
  EXPECT_THROW(single_oscillator_crossings(std::nan(""), 0.0, 1.0, 1.0), InvalidParameter);
  EXPECT_THROW(single_oscillator_crossings(0.1, 0.0, 0.0, 1.0), InvalidParameter);
}
