// Spectra of large banks (issue 6): the margin at N = 200 and 1000 checked by the certified spectrum just below
// and above τ_c (argument-principle counts on Δ, an independent route from the crossing search), convergence of
// τ_c(N) toward the N = ∞ value of docs/theory-control.md#delay-margin, and the rightmost roots at N = 400 checked by
// the Δ residual and the certified count.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/spectrum.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit::control;

namespace {
using afmkit_test::fig5::kGamma;
using afmkit_test::fig5::kT;

LoopSpec bank_loop(int n, double tau) {
  return LoopSpec(OscillatorBank::with_couplings(1.0, n, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, tau);
}
}  // namespace

TEST(LargeNSpectra, MarginIsConfirmedByCertifiedCountsAtN200) {
  const DelayMargin m = delay_margin(bank_loop(200, 0.0));
  ASSERT_TRUE(m.stable_at_reference);
  ASSERT_TRUE(std::isfinite(m.upper));
  EXPECT_EQ(unstable_roots(bank_loop(200, 0.97 * m.upper)).count, 0);
  EXPECT_EQ(unstable_roots(bank_loop(200, 1.03 * m.upper)).count, 2);  // one conjugate pair crossed
}

TEST(LargeNSpectra, MarginConvergesToTheInfiniteBank) {
  // docs/theory-control.md#delay-margin: τ_c/T = 0.294 for N = ∞ at (α, β) = (0.1, −0.1)Ω, K = γ
  const double inf = delay_margin(LoopSpec(InfiniteBank(1.0, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, 0.0)).upper;
  EXPECT_NEAR(inf / kT, 0.294, 5e-4);
  const double e100 = std::abs(delay_margin(bank_loop(100, 0.0)).upper - inf);
  const double e1000 = std::abs(delay_margin(bank_loop(1000, 0.0)).upper - inf);
  EXPECT_LT(e1000, e100);
  EXPECT_LT(e1000 / kT, 2e-3);
}

TEST(LargeNSpectra, RightmostRootsAtN400AreCertifiedRoots) {
  const LoopSpec loop = bank_loop(400, 0.1 * kT);
  SpectrumOptions o;
  o.count = 6;
  const Spectrum sp = rightmost_roots(loop, o);
  EXPECT_TRUE(sp.complete);
  ASSERT_FALSE(sp.roots.empty());
  for (const auto& r : sp.roots) {
    // Newton distance |Δ/Δ'| tiny: a root of the exact characteristic function
    const auto c = characteristic_scaled(loop, r.value);
    EXPECT_LT(std::abs(c.value / c.derivative), 1e-9 * (1.0 + std::abs(r.value))) << r.value;
  }
  // independent count: the certified box count equals the roots reported
  EXPECT_EQ(count_roots(loop, sp.box), sp.box_count);
  EXPECT_LT(sp.spectral_abscissa, 0.0);  // 0.1 T < τ_c
}
