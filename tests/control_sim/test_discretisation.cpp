// Discretisation tools: exact ZOH vs adaptive Runge–Kutta, φ-functions vs quadrature, AB3 stability region vs
// its closed-form real-axis limit, a direct AB3 recursion and an independent imaginary-axis bisection.
#include <gtest/gtest.h>

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "afmkit/control/discretisation.hpp"
#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/core/error.hpp"
#include "sim_test_helpers.hpp"

using namespace afmkit::control;

TEST(ZeroOrderHold, MatchesRungeKuttaForRandomSystem) {
  std::mt19937 rng(7);
  std::normal_distribution<double> nd;
  Eigen::MatrixXd a(5, 5), b(5, 1);
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) a(i, j) = nd(rng);
    b(i, 0) = nd(rng);
  }
  const double h = 0.3, v = 0.7;
  const ZeroOrderHold zoh = zero_order_hold(a, b, h);
  Eigen::VectorXd z0(5);
  for (int i = 0; i < 5; ++i) z0(i) = nd(rng);
  const Eigen::VectorXd ref = simref::integrate_linear(a, b.col(0) * v, z0, h);
  const Eigen::VectorXd got = zoh.transition * z0 + zoh.input.col(0) * v;
  EXPECT_LT((got - ref).norm(), 1e-11 * ref.norm());
}

TEST(ZeroOrderHold, MatchesRungeKuttaForControllerWithHeldSample) {
  // Controller ODE of eq. (15) with couplings (20), N = 4, sample held over h = T/40.
  const auto bank = OscillatorBank::with_couplings(1.0, 4, 0.1, -0.1, 20.0);
  const double h = 2.0 * std::numbers::pi / 40.0, m = -0.37;
  const ZeroOrderHold zoh = zero_order_hold(bank.state_matrix(), bank.input_vector(), h);
  Eigen::VectorXd z0 = Eigen::VectorXd::LinSpaced(bank.state_size(), -1.0, 1.0);
  const Eigen::VectorXd ref =
      simref::integrate_linear(bank.state_matrix(), bank.input_vector() * m, z0, h);
  EXPECT_LT((zoh.transition * z0 + zoh.input.col(0) * m - ref).norm(), 1e-12);
}

TEST(ZeroOrderHold, RejectsBadInput) {
  EXPECT_THROW(zero_order_hold(Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Ones(2, 1), 0.0),
               afmkit::InvalidParameter);
  EXPECT_THROW(zero_order_hold(Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Ones(3, 1), 0.1),
               afmkit::InvalidParameter);
}

TEST(PhiFunctions, MatchQuadratureOfTheExactPlantStep) {
  // ∫₀ʰ e^{λ(h−s)} s^j ds = j! h^{j+1} φ_{j+1}(λh), the weights of the exact step of plant (1).
  using boost::math::quadrature::gauss_kronrod;
  for (double lambda : {-20.0, -1e-4, 0.0, 3.0, -300.0}) {
    for (double h : {0.003, 0.5}) {
      double fact = 1.0;
      for (int j = 0; j < 4; ++j) {
        if (j > 0) fact *= j;
        auto f = [&](double s) { return std::exp(lambda * (h - s)) * std::pow(s, j); };
        const double ref = gauss_kronrod<double, 31>::integrate(f, 0.0, h, 10, 1e-15);
        const double got = fact * std::pow(h, j + 1) * phi_function(j + 1, lambda * h);
        EXPECT_NEAR(got, ref, 1e-13 * std::abs(ref)) << "lambda=" << lambda << " h=" << h << " j=" << j;
      }
    }
  }
}

TEST(PhiFunctions, ComplexAgreesWithClosedForm) {
  for (std::complex<double> z : {std::complex<double>(-0.1, 3.0), std::complex<double>(1e-3, -2e-3),
                                 std::complex<double>(-5.0, 0.5)}) {
    const std::complex<double> phi1 = (std::exp(z) - 1.0) / z;
    EXPECT_LT(std::abs(phi_function(1, z) - phi1), 1e-13 * std::abs(phi1));
    const std::complex<double> phi2 = (phi1 - 1.0) / z;
    EXPECT_LT(std::abs(phi_function(2, z) - phi2), 1e-10 * std::abs(phi2));
  }
  EXPECT_THROW(phi_function(9, 0.1), afmkit::InvalidParameter);
}

TEST(Ab3Region, RealAxisLimitIsMinusSixElevenths) {
  EXPECT_NEAR(ab3::real_axis_limit(), -6.0 / 11.0, 1e-15);
  EXPECT_NEAR(ab3::amplification(-6.0 / 11.0), 1.0, 1e-9);
  EXPECT_TRUE(ab3::is_stable(-0.54));
  EXPECT_FALSE(ab3::is_stable(-0.55));
}

TEST(Ab3Region, ImaginaryAxisLimitAgreesWithBisectionOnRootModulus) {
  // Independent algorithm: bisection of max|ζ| = 1 along w = iy (companion eigenvalues), versus the boundary-locus
  // root-finding inside imaginary_axis_limit().
  double lo = 0.5, hi = 0.9;
  ASSERT_LT(ab3::amplification({0.0, lo}), 1.0);
  ASSERT_GT(ab3::amplification({0.0, hi}), 1.0);
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ab3::amplification({0.0, mid}) < 1.0 ? lo : hi) = mid;
  }
  EXPECT_NEAR(ab3::imaginary_axis_limit(), lo, 1e-7);
  EXPECT_NEAR(lo, 0.7236, 1e-4);  // literature value of the AB3 imaginary stability interval
}

TEST(Ab3Region, BoundaryLocusHasUnitAmplification) {
  for (double theta : {0.3, 1.0, 2.0, 3.0}) EXPECT_NEAR(ab3::amplification(ab3::boundary(theta)), 1.0, 1e-9);
}

TEST(Ab3Region, DirectRecursionGrowsExactlyOutsideTheRegion) {
  // Run the AB3 recursion on y' = λy just inside and just outside the region.
  auto run = [](std::complex<double> w) {
    std::complex<double> y0 = 1.0, y1 = std::exp(w), y2 = std::exp(2.0 * w);
    for (int n = 0; n < 4000; ++n) {
      const std::complex<double> y3 = y2 + w * (23.0 * y2 - 16.0 * y1 + 5.0 * y0) / 12.0;
      y0 = y1;
      y1 = y2;
      y2 = y3;
    }
    return std::abs(y2);
  };
  const double lim = ab3::imaginary_axis_limit();
  EXPECT_LT(run({0.0, 0.98 * lim}), 1.0);
  EXPECT_GT(run({0.0, 1.02 * lim}), 10.0);
  EXPECT_LT(run({-0.53, 0.0}), 1.0);
  EXPECT_GT(run({-0.56, 0.0}), 10.0);
}

TEST(Ab3Region, MinimumStepsForUndampedOscillator) {
  // Mode ±10i (harmonic 10 of Ω = 1): need 2π·10/M < imaginary limit.
  Eigen::VectorXcd ev(2);
  ev << std::complex<double>(0.0, 10.0), std::complex<double>(0.0, -10.0);
  const double period = 2.0 * std::numbers::pi;
  const long expected = static_cast<long>(std::floor(period * 10.0 / ab3::imaginary_axis_limit())) + 1;
  EXPECT_EQ(ab3::minimum_steps(ev, period), expected);
}
