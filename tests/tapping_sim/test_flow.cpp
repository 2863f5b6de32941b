// Closed-form linear-mode flow (flow.hpp) against independent computations: the matrix exponential (Eigen)
// and a high-accuracy Runge–Kutta integration of the same ODE.
#include <cmath>
#include <numbers>

#include <boost/numeric/odeint.hpp>
#include <gtest/gtest.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/flow.hpp"

namespace afmkit::tapping {
namespace {

struct Case {
  double damping, stiffness, gamma, omega, force;
};

// ẍ + cẋ + kx = Γ cos ωt + f by Runge–Kutta–Fehlberg 7(8) at tight tolerance.
Eigen::Vector2d integrate(const Case& c, double t0, Eigen::Vector2d y0, double t1) {
  using State = std::array<double, 2>;
  State y{y0.x(), y0.y()};
  auto rhs = [&](const State& s, State& ds, double t) {
    ds[0] = s[1];
    ds[1] = c.gamma * std::cos(c.omega * t) + c.force - c.damping * s[1] - c.stiffness * s[0];
  };
  namespace odeint = boost::numeric::odeint;
  odeint::integrate_adaptive(odeint::make_controlled(1e-14, 1e-14, odeint::runge_kutta_fehlberg78<State>()), rhs, y,
                             t0, t1, 1e-3);
  return {y[0], y[1]};
}

class FlowCases : public ::testing::TestWithParam<Case> {};

TEST_P(FlowCases, PropagatorIsMatrixExponential) {
  const Case c = GetParam();
  const LinearModeFlow flow(c.damping, c.stiffness, c.gamma, c.omega, c.force, 0.0);
  Eigen::Matrix2d a;
  a << 0, 1, -c.stiffness, -c.damping;
  for (double tau : {0.0, 1e-3, 0.3, 1.7, 6.0, 25.0}) {
    const Eigen::Matrix2d expected = (a * tau).exp();
    EXPECT_LT((flow.propagator(tau) - expected).cwiseAbs().maxCoeff(), 1e-12 * std::max(1.0, expected.norm()))
        << "tau = " << tau;
  }
}

TEST_P(FlowCases, StateMatchesRungeKutta) {
  const Case c = GetParam();
  const LinearModeFlow flow(c.damping, c.stiffness, c.gamma, c.omega, c.force, 0.0);
  const Eigen::Vector2d y0(0.7, -1.3);
  for (double t0 : {0.0, 2.1}) {
    for (double tau : {0.5, 3.0, 11.0}) {
      const Eigen::Vector2d expected = integrate(c, t0, y0, t0 + tau);
      const Eigen::Vector2d got = flow.state(t0, y0, tau);
      EXPECT_NEAR(got.x(), expected.x(), 1e-10) << "t0 " << t0 << " tau " << tau;
      EXPECT_NEAR(got.y(), expected.y(), 1e-10) << "t0 " << t0 << " tau " << tau;
    }
  }
}

TEST_P(FlowCases, HomogeneousBoundHolds) {
  const Case c = GetParam();
  const LinearModeFlow flow(c.damping, c.stiffness, c.gamma, c.omega, c.force, 0.0);
  const Eigen::Vector2d h0(0.4, 2.5);
  const double bound = flow.homogeneous_bound(h0);
  for (double tau = 0; tau < 30; tau += 0.01) EXPECT_LE(std::abs((flow.propagator(tau) * h0).x()), bound * (1 + 1e-12));
}

INSTANTIATE_TEST_SUITE_P(DampingRegimes, FlowCases,
                         ::testing::Values(Case{0.01, 1.0, 0.2, 1.0, 0.0},      // underdamped, free (Q = 100)
                                           Case{0.01, 11.0, 0.2, 1.0, -100.0},  // stiff contact mode
                                           Case{2.0, 1.0, 0.5, 0.7, 0.3},       // critically damped (D = 0)
                                           Case{2.0, 1.0 - 1e-9, 0.5, 0.7, 0.3},  // nearly critical
                                           Case{5.0, 1.0, 0.5, 2.0, -0.2}));     // overdamped

TEST(Flow, SeparationSensitivityMatchesDifferenceQuotient) {
  // contact mode: f = −(F + K l), ∂(f/k)/∂l = −K/k
  const double c = 0.01, k0 = 1.0, ka = 10.0, fa = 0.3;
  auto flow_at = [&](double l) { return LinearModeFlow(c, k0 + ka, 0.2, 1.0, -(fa + ka * l), -ka / (k0 + ka)); };
  const Eigen::Vector2d y0(-10.2, -3.0);
  const double l = 10.0, dl = 1e-5;
  for (double tau : {0.1, 0.9}) {
    const Eigen::Vector2d fd = (flow_at(l + dl).state(0.3, y0, tau) - flow_at(l - dl).state(0.3, y0, tau)) / (2 * dl);
    const Eigen::Vector2d an = flow_at(l).separation_sensitivity(tau);
    EXPECT_NEAR(an.x(), fd.x(), 1e-8);
    EXPECT_NEAR(an.y(), fd.y(), 1e-8);
  }
}

TEST(Flow, RejectsInvalidCoefficients) {
  EXPECT_THROW(LinearModeFlow(0.01, 0.0, 0.2, 1.0, 0.0, 0.0), InvalidParameter);
  EXPECT_THROW(LinearModeFlow(-1.0, 1.0, 0.2, 1.0, 0.0, 0.0), InvalidParameter);
  EXPECT_THROW(LinearModeFlow(0.01, 1.0, 0.2, 0.0, 0.0, 0.0), InvalidParameter);
}

}  // namespace
}  // namespace afmkit::tapping
