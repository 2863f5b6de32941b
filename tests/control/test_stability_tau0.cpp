// τ = 0 stability (docs/theory-control.md#single-oscillator, #stability-tau0): conditions (13), (22), (40)–(42), (45),
// β_c(N), (24), against closed-loop eigenvalues (A − (K/γ) b c_1ᵀ for the static plant) and perturbed polynomial roots.
#include <gtest/gtest.h>

#include <numbers>

#include "afmkit/control/loop.hpp"
#include "afmkit/control/stability_tau0.hpp"
#include "afmkit/core/error.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit::control;
using cplx = std::complex<double>;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kGamma;

double abscissa(int n, double alpha, double beta) {
  return undelayed_spectral_abscissa(
      LoopSpec(OscillatorBank::with_couplings(kOmega, n, alpha, beta, kGamma), PlantKind::Static, kGamma, 0.0));
}

// β_c by bisection on the eigenvalues (independent of the crossing formula).
double beta_by_bisection(int n, double alpha) {
  double lo = -0.6 * kOmega, hi = 0.0;  // unstable at lo, stable at hi
  EXPECT_GT(abscissa(n, alpha, lo), 0.0);
  EXPECT_LT(abscissa(n, alpha, hi), 0.0);
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (abscissa(n, alpha, mid) < 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}
}  // namespace

TEST(StabilityTau0, OneOscillatorEq13MatchesEigenvalues) {
  int mismatches = 0, total = 0;
  for (double kappa : {0.5, 1.0, 3.0}) {
    for (int i = 0; i <= 40; ++i) {
      for (int j = 0; j <= 60; ++j) {
        const double a = -2.0 + 0.1 * i, b = -3.0 + 0.1 * j;
        if (std::abs(a) < 1e-9 || std::abs(b - kOmega / kappa) < 1e-6) continue;  // on the border
        const LoopSpec loop(OscillatorBank::single(kOmega, a, b, kappa * kGamma), PlantKind::Static, kGamma, 0.0);
        const bool by_eig = undelayed_spectral_abscissa(loop) < 0.0;
        mismatches += by_eig != single_oscillator_stable_tau0(kOmega, a, b, kappa * kGamma, kGamma);
        ++total;
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(total, 7000);
}

TEST(StabilityTau0, PolynomialEq22RootsAreClosedLoopEigenvalues) {
  double worst = 0.0;
  for (int n : {2, 5, 10, 15}) {
    for (auto [alpha, beta] : {std::pair{0.3, 0.1}, {1.0, -0.2}, {0.05, 0.5}}) {
      const Polynomial p = closed_loop_polynomial(n, kOmega, alpha, beta);
      ASSERT_EQ(p.degree(), 2 * n + 1);
      EXPECT_DOUBLE_EQ(p.leading(), 1.0);
      const auto ev = undelayed_poles(
          LoopSpec(OscillatorBank::with_couplings(kOmega, n, alpha, beta, kGamma), PlantKind::Static, kGamma, 0.0));
      for (const auto& r : p.roots()) {
        double best = 1e9;
        for (const auto& e : ev) best = std::min(best, std::abs(r - e));
        worst = std::max(worst, best);
      }
      // the same polynomial from the general bank formula (tf(bank) with K = γ)
      const Polynomial q = closed_loop_polynomial(OscillatorBank::with_couplings(kOmega, n, alpha, beta, kGamma), kGamma);
      for (int j = 0; j <= p.degree(); ++j)
        EXPECT_NEAR(q.coefficient(j), p.coefficient(j), 1e-12 * std::abs(p.coefficient(j)) + 1e-300) << n << " " << j;
    }
  }
  EXPECT_LT(worst, 1e-7);
}

TEST(StabilityTau0, NecessaryConditions40To42MatchCoefficients) {
  for (int n : {1, 3, 8}) {
    for (auto [alpha, beta] : {std::pair{0.3, 0.1}, {-0.2, -0.35}}) {
      const Polynomial p = closed_loop_polynomial(n, kOmega, alpha, beta);
      const auto c = necessary_conditions(n, kOmega, alpha, beta);
      double p0 = 1.0;
      for (int k = 1; k <= n; ++k) p0 *= k * k * kOmega * kOmega;
      EXPECT_NEAR(c.coefficient_2n, p.coefficient(2 * n), 1e-12 * (1.0 + std::abs(p.coefficient(2 * n))));
      EXPECT_NEAR(c.coefficient_1_normalised, p.coefficient(1) / p0, 1e-12);
      EXPECT_EQ(c.alpha_positive, alpha > 0.0);
    }
  }
  EXPECT_TRUE(necessary_conditions(5, kOmega, 0.1, -0.3).limit_condition);    // −0.3 > −3/π² = −0.30396
  EXPECT_FALSE(necessary_conditions(5, kOmega, 0.1, -0.31).limit_condition);
}

TEST(StabilityTau0, CriticalBetaMatchesBisectionOnEigenvaluesAndIsIndependentOfAlpha) {
  for (int n : {1, 2, 3, 5, 10}) {
    const double bc = critical_beta(n, kOmega).beta;
    for (double alpha : {0.02, 0.3, 2.0}) EXPECT_NEAR(beta_by_bisection(n, alpha), bc, 1e-7) << n << " " << alpha;
  }
  EXPECT_NEAR(beta_by_bisection(40, 0.3), critical_beta(40, kOmega).beta, 1e-7);
}

TEST(StabilityTau0, CriticalBetaValuesOfMathMdB5AndLimitEq24) {
  const std::vector<std::pair<int, double>> table{{1, -0.33333}, {2, -0.29584}, {3, -0.28159}, {5, -0.26947},
                                                  {10, -0.25993}, {20, -0.25502}, {40, -0.25252}, {160, -0.25063}};
  double prev = -1.0;
  for (auto [n, value] : table) {
    const auto c = critical_beta(n, 2.0);  // scales with Ω
    EXPECT_NEAR(c.beta / 2.0, value, 6e-6) << n;
    EXPECT_GT(c.beta / 2.0, prev);
    prev = c.beta / 2.0;
    EXPECT_GT(c.crossing_frequency, 0.0);
    EXPECT_LT(c.crossing_frequency, 2.0);
  }
  EXPECT_NEAR(critical_beta(1, kOmega).crossing_frequency, 1.0 / std::sqrt(3.0), 1e-14);  // ν² = Ω²/3
  EXPECT_NEAR(critical_beta(1, kOmega).beta, -1.0 / 3.0, 1e-14);
  EXPECT_NEAR(critical_beta(100000, kOmega).beta, -0.25, 1e-5);
  EXPECT_NEAR(critical_beta(100000, kOmega).crossing_frequency, 0.5, 1e-5);
  EXPECT_DOUBLE_EQ(critical_beta_limit(kOmega).beta, -0.25);
  EXPECT_TRUE(infinite_bank_stable_tau0(kOmega, 0.1, -0.24));
  EXPECT_FALSE(infinite_bank_stable_tau0(kOmega, 0.1, -0.26));
  EXPECT_FALSE(infinite_bank_stable_tau0(kOmega, -0.01, 0.5));
}

TEST(StabilityTau0, CouplingsConditionMatchesEigenvaluesOnAGrid) {
  int mismatches = 0;
  for (int n : {1, 3, 8}) {
    const double bc = critical_beta(n, kOmega).beta;
    for (double alpha : {-0.5, -0.01, 0.01, 0.3, 1.0, 5.0}) {
      for (double beta : {-1.0, -0.4, bc - 0.01, bc + 0.01, -0.1, 0.0, 0.5, 2.0, 10.0, 50.0, 300.0}) {
        const bool by_eig = abscissa(n, alpha, beta) < 0.0;
        mismatches += by_eig != couplings_stable_tau0(n, kOmega, alpha, beta);
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(StabilityTau0, RootSensitivityEq45MatchesPerturbedRoots) {
  const int n = 8;
  const double eps = 1e-4;  // central differences: truncation O(eps²), rounding ~1e-12/eps
  const auto r0 = closed_loop_polynomial(n, kOmega, 0.0, 0.0).roots();
  const auto ra_p = closed_loop_polynomial(n, kOmega, eps, 0.0).roots();
  const auto ra_m = closed_loop_polynomial(n, kOmega, -eps, 0.0).roots();
  const auto rb_p = closed_loop_polynomial(n, kOmega, 0.0, eps).roots();
  const auto rb_m = closed_loop_polynomial(n, kOmega, 0.0, -eps).roots();
  ASSERT_EQ(r0.size(), 2u * n + 1u);
  for (const auto& r : r0) {
    const int k = static_cast<int>(std::lround(r.imag() / kOmega));
    EXPECT_LT(std::abs(r - cplx(0.0, k * kOmega)), 1e-9);  // α = β = 0: roots ikΩ
    auto nearest = [&](const std::vector<cplx>& v) {
      return *std::min_element(v.begin(), v.end(), [&](cplx x, cplx y) { return std::abs(x - r) < std::abs(y - r); });
    };
    const auto [da, db] = root_sensitivity_at_origin(k);
    EXPECT_LT(std::abs((nearest(ra_p) - nearest(ra_m)) / (2.0 * eps) - da), 1e-6) << k;
    EXPECT_LT(std::abs((nearest(rb_p) - nearest(rb_m)) / (2.0 * eps) - db), 1e-6) << k;
  }
}

TEST(StabilityTau0, BadInputNamesTheParameter) {
  auto name_of = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const afmkit::InvalidParameter& e) {
      return e.parameter();
    }
    return "";
  };
  EXPECT_EQ(name_of([] { critical_beta(0, 1.0); }), "harmonics");
  EXPECT_EQ(name_of([] { critical_beta(3, 0.0); }), "rotation_frequency");
  EXPECT_EQ(name_of([] { closed_loop_polynomial(3, 1.0, std::nan(""), 0.0); }), "alpha");
  EXPECT_EQ(name_of([] { necessary_conditions(2, -1.0, 0.1, 0.0); }), "rotation_frequency");
  EXPECT_EQ(name_of([] { single_oscillator_stable_tau0(1.0, 0.1, 0.0, 1.0, 0.0); }), "plant_rate");
}
