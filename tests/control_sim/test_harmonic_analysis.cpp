// Harmonic analysis: exact Fourier projection of sampled trigonometric polynomials, uncontrolled steady state of
// plant (1) against a direct Runge–Kutta integration, and the log-envelope fit on synthetic envelopes.
#include <gtest/gtest.h>

#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <numbers>

#include "afmkit/control/harmonic_analysis.hpp"
#include "afmkit/core/error.hpp"

using namespace afmkit::control;
using cd = std::complex<double>;

TEST(FourierCoefficients, ExactForTrigonometricPolynomial) {
  const int m = 64;
  std::vector<double> s(m);
  for (int n = 0; n < m; ++n) {
    const double th = 2.0 * std::numbers::pi * n / m;
    s[n] = 0.3 + 2.0 * std::sin(th + 0.4) + 0.5 * std::cos(3.0 * th) - 0.1 * std::sin(31.0 * th);
  }
  const auto c = fourier_coefficients(s, 31);
  EXPECT_NEAR(c[0].real(), 0.3, 1e-14);
  EXPECT_LT(std::abs(c[1] - cd(0, -1) * std::polar(2.0, 0.4)), 1e-14);
  EXPECT_LT(std::abs(c[2]), 1e-14);
  EXPECT_LT(std::abs(c[3] - 0.5), 1e-14);
  EXPECT_LT(std::abs(c[31] - cd(0, 0.1)), 1e-14);
  EXPECT_THROW(fourier_coefficients(s, 32), afmkit::InvalidParameter);
  EXPECT_THROW(fourier_coefficients({}, 0), afmkit::InvalidParameter);
}

TEST(DisturbanceHarmonics, ComplexAmplitudeConvention) {
  const Disturbance f(0.2, {{1, 1.0, 0.0}, {3, 0.5, 0.7}});
  EXPECT_EQ(disturbance_harmonic(f, 0), cd(0.2, 0.0));
  for (double th : {0.0, 0.9, 2.5}) {
    const double rebuilt = 0.2 + (disturbance_harmonic(f, 1) * std::polar(1.0, th)).real() +
                           (disturbance_harmonic(f, 3) * std::polar(1.0, 3.0 * th)).real();
    EXPECT_NEAR(rebuilt, f(th), 1e-15);
  }
  EXPECT_EQ(disturbance_harmonic(f, 2), cd(0.0, 0.0));
}

TEST(UncontrolledOutput, FirstOrderPlantMatchesDirectIntegration) {
  // ẏ = −γ (y − f(Ωt)) from y = 0; after 30/γ the transient e^{−γt} is gone and y equals the periodic steady state.
  const Plant plant(PlantKind::FirstOrder, 7.0, 1.3, 0.0, Disturbance::paper_example(5));
  namespace odeint = boost::numeric::odeint;
  double y = 0.0, t = 0.0;
  auto rhs = [&](const double& x, double& dx, double tt) { dx = -plant.rate * (x - plant.disturbance(plant.rotation_frequency * tt)); };
  for (double t_end : {6.0, 7.1, 9.3}) {
    odeint::integrate_adaptive(odeint::make_controlled<odeint::runge_kutta_dopri5<double>>(1e-13, 1e-13), rhs, y, t,
                               t_end, 1e-3);
    t = t_end;
    EXPECT_NEAR(y, uncontrolled_output(plant, t), 1e-10) << t;
  }
  // target = uncontrolled output without the rejected harmonics
  const std::vector<int> rej{1};
  const cd y1 = uncontrolled_harmonic(plant, 1);
  EXPECT_NEAR(target_output(plant, 0.4, rej), uncontrolled_output(plant, 0.4) - (y1 * std::polar(1.0, 1.3 * 0.4)).real(),
              1e-14);
  EXPECT_LT(std::abs(y1 - 7.0 * disturbance_harmonic(plant.disturbance, 1) / cd(7.0, 1.3)), 1e-15);
}

TEST(EnvelopeFit, DecayingEnvelopeWithFloor) {
  const double period = 2.0;
  std::vector<double> env;
  for (int p = 0; p < 40; ++p) env.push_back(std::exp(-0.7 * (p + 0.5) * period) + 1e-9);
  env[0] = 5.0;  // start transient, excluded (window starts at period 1)
  const EnvelopeFit fit = fit_log_envelope(env, period);
  EXPECT_EQ(fit.first_period, 1);
  EXPECT_GT(fit.last_period, 5);
  EXPECT_LT(fit.last_period, 12);  // stops before the floor: e^{−1.4p} > 1e-7 ⇔ p < 11.5
  EXPECT_NEAR(fit.growth_rate, -0.7, 0.01);
}

TEST(EnvelopeFit, GrowingEnvelopeUsesSecondHalf) {
  std::vector<double> env;
  for (int p = 0; p < 30; ++p) env.push_back(1e-3 * std::exp(0.05 * (p + 0.5)) + (p < 5 ? 1.0 : 0.0));
  const EnvelopeFit fit = fit_log_envelope(env, 1.0);
  EXPECT_EQ(fit.first_period, 15);
  EXPECT_NEAR(fit.growth_rate, 0.05, 1e-12);
}
