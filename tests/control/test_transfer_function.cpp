// Polynomials and rational transfer functions, and the exact rational controller vs its state space.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "afmkit/control/state_space.hpp"
#include "afmkit/control/transfer_function.hpp"
#include "afmkit/core/error.hpp"
#include "test_helpers.hpp"

using namespace afmkit::control;
using afmkit::InvalidParameter;
using afmkit::control::testing::random_points;
using afmkit::control::testing::rel_err;
using cplx = std::complex<double>;

TEST(Polynomial, ArithmeticAndEvaluation) {
  const auto p = Polynomial::from_descending({1.0, -3.0, 2.0});  // s² − 3s + 2 = (s − 1)(s − 2)
  EXPECT_EQ(p.degree(), 2);
  EXPECT_DOUBLE_EQ(p.coefficient(0), 2.0);
  EXPECT_EQ(p.descending(), (std::vector<double>{1.0, -3.0, 2.0}));
  const auto q = Polynomial({-1.0, 1.0}) * Polynomial({-2.0, 1.0});
  EXPECT_EQ(q.ascending(), p.ascending());
  EXPECT_TRUE((p - q).is_zero());
  EXPECT_EQ((p + Polynomial({0.0, 3.0, -1.0})).degree(), 0);  // trailing zeros trimmed
  EXPECT_EQ(p.derivative().ascending(), (std::vector<double>{-3.0, 2.0}));
  const cplx s(0.3, -1.7);
  EXPECT_LT(std::abs(p(s) - (s - 1.0) * (s - 2.0)), 1e-14);
}

TEST(Polynomial, RootsOfProductOfKnownFactors) {
  std::vector<cplx> r{{-1.0, 0.0}, {-0.5, 3.0}, {-0.5, -3.0}, {2.0, 0.0}, {0.0, 0.0}, {-0.1, 7.0}, {-0.1, -7.0}};
  const auto p = Polynomial::from_roots(r);
  auto found = p.roots();
  ASSERT_EQ(found.size(), r.size());
  for (const auto& z : r) {
    double best = 1e9;
    for (const auto& f : found) best = std::min(best, std::abs(f - z));
    EXPECT_LT(best, 1e-12) << z;
  }
  EXPECT_THROW(Polynomial::from_roots({{1.0, 1.0}}), InvalidParameter);
}

TEST(TransferFunction, AlgebraMatchesPointwiseValues) {
  const auto g = tf({1.0, 2.0}, {1.0, 0.5, 4.0});
  const auto h = tf({3.0}, {1.0, 1.0});
  double worst = 0.0;
  for (auto s : random_points(11, 20)) {
    const cplx a = (s + 2.0) / (s * s + 0.5 * s + 4.0), b = 3.0 / (s + 1.0);
    worst = std::max(worst, rel_err((g * h)(s), a * b));
    worst = std::max(worst, rel_err((g + h)(s), a + b));
    worst = std::max(worst, rel_err((g - h)(s), a - b));
    worst = std::max(worst, rel_err((g / h)(s), a / b));
    worst = std::max(worst, rel_err(feedback(g, h)(s), a / (1.0 + a * b)));
    worst = std::max(worst, rel_err(feedback(g, 2.0, +1)(s), a / (1.0 - 2.0 * a)));
  }
  EXPECT_LT(worst, 1e-13);
  EXPECT_TRUE(std::isinf(tf({1.0}, {1.0, 0.0})(0.0).real()));  // exactly at a pole
  EXPECT_THROW(tf({1.0}, {0.0}), InvalidParameter);
}

TEST(TransferFunction, BankRationalFormMatchesStateSpace) {
  std::mt19937 rng(5);
  std::normal_distribution<double> nd;
  const double omega = 1.3;
  double worst = 0.0;
  for (int n = 1; n <= 6; ++n) {
    for (int trial = 0; trial < 4; ++trial) {
      std::vector<double> a(n), b(n);
      for (int k = 0; k < n; ++k) {
        a[k] = nd(rng);
        b[k] = nd(rng);
      }
      std::vector<int> rejected{1};
      if (n >= 3 && trial % 2) rejected = {1, 3};
      const double a0 = trial == 3 ? 0.0 : nd(rng);  // a0 = 0: no integrator
      const OscillatorBank bank(omega, a0, a, b, 0.5 + std::abs(nd(rng)), rejected);
      const auto c = tf(bank);
      const auto g = ss(bank);
      for (auto s : random_points(20 + n, 12)) worst = std::max(worst, rel_err(c(s), g(s)));
      // denominator = det(sI − A) (x0 dropped when a0 = 0): same roots as the eigenvalues of A
      if (a0 != 0.0) {
        const auto ev = g.poles();
        for (int i = 0; i < ev.size(); ++i)
          EXPECT_LT(std::abs(c.den()(ev(i))) / std::abs(c.den().derivative()(ev(i))), 1e-8 * (1 + std::abs(ev(i))));
      }
    }
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(TransferFunction, PlantForms) {
  const cplx s(0.2, 3.0);
  EXPECT_LT(std::abs(tf(PlantKind::Static, 20.0)(s) - 0.05), 1e-16);
  EXPECT_LT(std::abs(tf(PlantKind::FirstOrder, 20.0)(s) - 1.0 / (s + 20.0)), 1e-16);
  EXPECT_THROW(tf(PlantKind::Static, 0.0), InvalidParameter);
}
