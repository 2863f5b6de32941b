// Rightmost roots: Newton-refined roots vs an independent full-state collocation of the DDE, vs the τ = 0
// closed-loop eigenvalues and polynomial (22), argument-principle counts, N = ∞ neutral form (B.7/B.8).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "afmkit/control/dde_collocation.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/core/error.hpp"
#include "reference.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit;
using namespace afmkit::control;
using test::cplx;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kGamma;
using afmkit_test::fig5::kT;

// Every root in the box matches a reference eigenvalue and every reference eigenvalue well inside the box is found.
void expect_matches_reference(const Spectrum& sp, const std::vector<cplx>& ref, double tol) {
  std::vector<cplx> found;
  for (const auto& r : sp.roots) found.push_back(r.value);
  int inner = 0;
  for (const auto& r : sp.roots) EXPECT_LT(test::distance(ref, r.value), tol) << r.value;
  for (const cplx& e : ref) {
    const Box& b = sp.box;
    const double m = 1e-3;
    if (e.real() > b.real_min + m && e.real() < b.real_max - m && std::abs(e.imag()) < b.imag_max - m &&
        std::abs(e) < 12.0) {
      ++inner;
      EXPECT_LT(test::distance(found, e), tol) << "reference eigenvalue " << e << " not found";
    }
  }
  EXPECT_GT(inner, 0);
}
}  // namespace

TEST(Spectrum, SingleOscillatorMatchesCollocationAndMathMd) {
  const auto bank = OscillatorBank::single(kOmega, 0.5, 0.0, kGamma);
  const LoopSpec loop(bank, PlantKind::Static, kGamma, 0.2 * kT);
  const Spectrum sp = rightmost_roots(loop);
  ASSERT_TRUE(sp.complete);
  EXPECT_TRUE(sp.box_is_proven);
  // Fig. 3 case (docs/theory-control.md#simulation): rightmost root +0.0102 for τ = 0.2T (simulation diverges)
  EXPECT_NEAR(sp.spectral_abscissa, 0.0102, 5e-5);
  EXPECT_EQ(sp.unstable_count, 2);
  expect_matches_reference(sp, test::reference_roots(bank, PlantKind::Static, kGamma, 0.2 * kT, 60), 1e-8);
  for (const auto& r : sp.roots) {
    EXPECT_TRUE(r.certified);
    EXPECT_EQ(r.multiplicity, 1);
    EXPECT_LE(r.correction, 1e-12 * std::max(1.0, std::abs(r.value)));
  }
}

TEST(Spectrum, BankStaticAndFirstOrderMatchCollocation) {
  {
    const auto bank = OscillatorBank::with_couplings(kOmega, 4, 0.1, -0.1, kGamma);
    const LoopSpec loop(bank, PlantKind::Static, kGamma, 0.1 * kT);
    const Spectrum sp = rightmost_roots(loop);
    ASSERT_TRUE(sp.complete);
    EXPECT_GE(sp.roots.size(), 8u);
    expect_matches_reference(sp, test::reference_roots(bank, PlantKind::Static, kGamma, 0.1 * kT, 40), 1e-8);
  }
  {
    const auto bank = OscillatorBank::with_couplings(kOmega, 3, 0.3, 0.1, 8.0, {1, 3});
    const LoopSpec loop(bank, PlantKind::FirstOrder, 10.0, 0.3 * kT);
    const Spectrum sp = rightmost_roots(loop);
    ASSERT_TRUE(sp.complete);
    expect_matches_reference(sp, test::reference_roots(bank, PlantKind::FirstOrder, 10.0, 0.3 * kT, 40), 1e-8);
  }
}

TEST(Spectrum, DelayFreeRootsAreClosedLoopEigenvaluesAndPolynomial22) {
  const int n = 5;
  const auto bank = OscillatorBank::with_couplings(kOmega, n, 0.3, 0.1, kGamma);
  const LoopSpec loop(bank, PlantKind::Static, kGamma, 0.0);
  SpectrumOptions o;
  o.min_real = -10.0;
  const Spectrum sp = rightmost_roots(loop, o);
  ASSERT_TRUE(sp.complete);
  EXPECT_EQ(sp.box_count, 2 * n + 1);  // all 2N+1 roots of the polynomial (22)
  const auto eig = undelayed_poles(loop);
  const auto poly = closed_loop_polynomial(n, kOmega, 0.3, 0.1).roots();
  for (const auto& r : sp.roots) {
    EXPECT_LT(test::distance(eig, r.value), 1e-9);
    EXPECT_LT(test::distance(poly, r.value), 1e-7);
  }
}

TEST(Spectrum, ArgumentPrincipleCountsRefinedRoots) {
  const auto bank = OscillatorBank::with_couplings(kOmega, 3, 0.2, -0.05, kGamma);
  const LoopSpec loop(bank, PlantKind::Static, kGamma, 0.25 * kT);
  const auto ref = test::reference_roots(bank, PlantKind::Static, kGamma, 0.25 * kT, 60);
  // boxes of various sizes: count = number of reference eigenvalues inside
  const Box boxes[] = {{-0.3, 0.5, -4.0, 4.0}, {-0.25, 0.1, 0.5, 1.5}, {-1.0, 0.2, -0.4, 2.6}, {-0.5, 1.0, 3.4, 9.2}};
  for (const Box& b : boxes) {
    int expected = 0;
    for (const cplx& e : ref)
      if (e.real() > b.real_min && e.real() < b.real_max && e.imag() > b.imag_min && e.imag() < b.imag_max) ++expected;
    EXPECT_EQ(count_roots(loop, b), expected) << b.real_min << " " << b.real_max << " " << b.imag_min << " " << b.imag_max;
  }
  const Spectrum sp = rightmost_roots(loop);
  int sum = 0;
  for (const auto& r : sp.roots) sum += r.multiplicity;
  EXPECT_EQ(sum, sp.box_count);
  EXPECT_TRUE(sp.complete);
}

TEST(Spectrum, CollocationLibraryAgreesWithFullStateReference) {
  const auto bank = OscillatorBank::with_couplings(kOmega, 4, 0.15, -0.1, kGamma, {1, 2});
  const LoopSpec loop(bank, PlantKind::FirstOrder, kGamma, 0.4 * kT);
  const auto lib = collocation_eigenvalues(closed_loop_dde(loop), 50);
  const auto ref = test::reference_roots(bank, PlantKind::FirstOrder, kGamma, 0.4 * kT, 50);
  int checked = 0;
  for (const cplx& e : ref)
    if (std::abs(e) < 6.0 && e.real() > -1.0) {
      EXPECT_LT(test::distance(lib, e), 1e-7) << e;
      ++checked;
    }
  EXPECT_GT(checked, 6);
  // differentiation matrix is exact on polynomials of degree ≤ n
  const int n = 8;
  const Eigen::MatrixXd d = chebyshev_differentiation(n);
  Eigen::VectorXd p(n + 1), dp(n + 1);
  for (int j = 0; j <= n; ++j) {
    const double x = std::cos(std::numbers::pi * j / n);
    p(j) = std::pow(x, 7) - 2.0 * x * x;
    dp(j) = 7.0 * std::pow(x, 6) - 4.0 * x;
  }
  EXPECT_LT((d * p - dp).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Spectrum, InfiniteBankNeutralChainAndStructuralRoots) {
  const InfiniteBank bank(kOmega, 0.5, 0.0, kGamma);
  const double tau = 0.1 * kT;
  const LoopSpec loop(bank, PlantKind::Static, kGamma, tau);
  const Spectrum sp = rightmost_roots(loop);
  ASSERT_TRUE(sp.complete);
  ASSERT_TRUE(sp.neutral_bound.has_value());
  const double r = (1.0 - std::numbers::pi * 0.5) / (1.0 + std::numbers::pi * 0.5);
  EXPECT_NEAR(*sp.neutral_bound, std::log(std::abs(r)) / kT, 1e-14);
  EXPECT_GT(sp.spectral_abscissa, 0.0);  // τ = 0.1T > τ_c = 0.089T
  EXPECT_EQ(sp.unstable_count, 2);
  // every root is a zero of the neutral quasi-polynomial built from the 𝒜, ℬ, 𝒩 coefficients (seed-2 eq. 31)
  for (const auto& root : sp.roots) {
    const cplx s = root.value;
    const double scale = std::abs(test::neutral_quasi_polynomial(bank, kGamma, tau, s + 1e-3)) / 1e-3;
    EXPECT_LT(std::abs(test::neutral_quasi_polynomial(bank, kGamma, tau, s)), 1e-9 * scale) << s;
  }
  // B.8: double root at 0 and simple roots at ±iΩ of the realisation, exactly on the imaginary axis
  ASSERT_EQ(sp.structural.size(), 3u);
  EXPECT_EQ(sp.structural[0].multiplicity, 2);
  EXPECT_EQ(sp.structural[1].multiplicity, 1);
  EXPECT_EQ(sp.structural[2].multiplicity, 1);
  for (const auto& s : sp.structural) EXPECT_LT(std::abs(test::neutral_quasi_polynomial(bank, kGamma, tau, s.value)), 1e-12);
  // roots far up the chain approach Re s = bound
  const CharacteristicRoot far = refine_root(loop, cplx(*sp.neutral_bound, 60.3 * kOmega));
  EXPECT_NEAR(far.value.real(), *sp.neutral_bound, 0.02);
}

TEST(Spectrum, InfiniteBankIsTheLimitOfTruncatedBanks) {
  const double tau = 0.15 * kT;
  const LoopSpec inf(InfiniteBank(kOmega, 0.2, -0.1, kGamma), PlantKind::Static, kGamma, tau);
  const LoopSpec n40(OscillatorBank::with_couplings(kOmega, 40, 0.2, -0.1, kGamma), PlantKind::Static, kGamma, tau);
  const cplx a = rightmost_roots(inf).roots.front().value;
  const cplx b = refine_root(n40, a).value;  // same root of the truncated loop, O(1/N) away
  EXPECT_LT(std::abs(a - b), 0.02);
  EXPECT_GT(std::abs(a - b), 0.0);
}

TEST(Spectrum, UnstableCountsAndMarginalCases) {
  // α ≤ 0 for N = ∞: the neutral chain lies in Re s ≥ 0
  const LoopSpec neg(InfiniteBank(kOmega, -0.05, 0.0, kGamma), PlantKind::Static, kGamma, 0.0);
  EXPECT_EQ(unstable_roots(neg).count, -1);
  // one oscillator with a = 0 at τ = 0: roots ±i√(Ω² − ρbΩ) on the imaginary axis: marginal
  const LoopSpec marg(OscillatorBank::single(kOmega, 0.0, 0.3, kGamma), PlantKind::Static, kGamma, 0.0);
  EXPECT_TRUE(unstable_roots(marg).marginal);
  // b above γΩ/K: one real unstable root (eq. 13)
  const LoopSpec real(OscillatorBank::single(kOmega, 0.5, 1.2, kGamma), PlantKind::Static, kGamma, 0.1 * kT);
  EXPECT_EQ(unstable_roots(real).count, 1);
}

TEST(Spectrum, DelayBeyondPeriodIsAllowed) {
  const LoopSpec loop(OscillatorBank::with_couplings(kOmega, 2, 0.05, -0.05, kGamma), PlantKind::Static, kGamma, 1.3 * kT);
  const Spectrum sp = rightmost_roots(loop);
  EXPECT_TRUE(sp.complete);
  expect_matches_reference(sp, test::reference_roots(OscillatorBank::with_couplings(kOmega, 2, 0.05, -0.05, kGamma),
                                                     PlantKind::Static, kGamma, 1.3 * kT, 90),
                           1e-7);
}

TEST(Spectrum, BadInputNamesTheParameter) {
  const auto expect_param = [](auto f, const std::string& name) {
    try {
      f();
      ADD_FAILURE() << "no exception for " << name;
    } catch (const InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), name) << e.what();
    }
  };
  expect_param([] { LoopSpec(OscillatorBank::single(kOmega, 0.5, 0, kGamma), PlantKind::Static, kGamma, -0.1); }, "delay");
  expect_param([] { OscillatorBank::with_couplings(kOmega, 0, 0.1, 0.1, kGamma); }, "harmonics");
  expect_param([] { InfiniteBank(kOmega, std::nan(""), 0.1, kGamma); }, "alpha");
  expect_param([] { OscillatorBank::with_couplings(kOmega, 3, 0.1, std::nan(""), kGamma); }, "beta");
  const LoopSpec loop(OscillatorBank::single(kOmega, 0.5, 0, kGamma), PlantKind::Static, kGamma, 0.1);
  expect_param([&] {
    SpectrumOptions o;
    o.tolerance = 0.5;
    rightmost_roots(loop, o);
  }, "tolerance");
  expect_param([&] { count_roots(loop, Box{0.0, -1.0, -1.0, 1.0}); }, "real_max");
  expect_param([&] { refine_root(loop, cplx(std::nan(""), 0.0)); }, "guess.real");
  expect_param([&] { collocation_eigenvalues(closed_loop_dde(loop), -3); }, "nodes");
}
