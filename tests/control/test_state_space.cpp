// LTI toolbox: StateSpace evaluation, series/parallel/feedback against closed-form algebra.
#include <gtest/gtest.h>

#include "afmkit/control/state_space.hpp"
#include "afmkit/control/transfer_function.hpp"
#include "afmkit/core/error.hpp"
#include "test_helpers.hpp"

using namespace afmkit::control;
using afmkit::InvalidParameter;
using afmkit::control::testing::random_points;
using afmkit::control::testing::rel_err;
using cplx = std::complex<double>;

namespace {
// A 2-state system with an explicit 2×2 inverse: G = C adj(sI − A) B / det + D.
StateSpace two_state() {
  Eigen::MatrixXd a(2, 2), b(2, 1), c(1, 2), d(1, 1);
  a << -1.0, 2.0, -3.0, -0.5;
  b << 1.0, -2.0;
  c << 0.5, 1.5;
  d << 0.25;
  return ss(a, b, c, d);
}
cplx two_state_formula(cplx s) {
  const cplx m00 = s + 1.0, m01 = -2.0, m10 = 3.0, m11 = s + 0.5;  // sI − A
  const cplx det = m00 * m11 - m01 * m10;
  const cplx x0 = (m11 * 1.0 - m01 * -2.0) / det, x1 = (-m10 * 1.0 + m00 * -2.0) / det;
  return 0.5 * x0 + 1.5 * x1 + 0.25;
}
}  // namespace

TEST(StateSpace, EvaluationMatchesExplicitInverse) {
  const auto g = two_state();
  double worst = 0.0;
  for (auto s : random_points(1, 30)) worst = std::max(worst, rel_err(g(s), two_state_formula(s)));
  EXPECT_LT(worst, 1e-14);
}

TEST(StateSpace, PolesAreEigenvalues) {
  const auto p = two_state().poles();
  // det(sI − A) = s² + 1.5 s + 6.5 → s = −0.75 ± i sqrt(6.5 − 0.5625)
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(p(i).real(), -0.75, 1e-13);
    EXPECT_NEAR(std::abs(p(i).imag()), std::sqrt(6.5 - 0.5625), 1e-13);
  }
}

TEST(StateSpace, SeriesParallelFeedbackMatchAlgebra) {
  const auto g1 = two_state();
  const auto g2 = ss(PlantKind::FirstOrder, 3.0);  // 1/(s + 3)
  const auto gs = ss(0.7);                          // static gain, no states
  const auto ser = series(g1, g2), par = parallel(g1, g2);
  const auto fb = feedback(g1, g2), fbp = feedback(g1, g2, +1), fbs = feedback(g1, gs), fb1 = feedback(g1);
  double worst = 0.0;
  for (auto s : random_points(2, 30)) {
    const cplx a = two_state_formula(s), b = 1.0 / (s + 3.0);
    worst = std::max(worst, rel_err(ser(s), a * b));
    worst = std::max(worst, rel_err(par(s), a + b));
    worst = std::max(worst, rel_err(fb(s), a / (1.0 + a * b)));
    worst = std::max(worst, rel_err(fbp(s), a / (1.0 - a * b)));
    worst = std::max(worst, rel_err(fbs(s), a / (1.0 + 0.7 * a)));
    worst = std::max(worst, rel_err(fb1(s), a / (1.0 + a)));
  }
  EXPECT_LT(worst, 1e-13);
}

TEST(StateSpace, FeedbackAgreesWithTransferFunctionFeedback) {
  const auto g = tf({2.0, 1.0}, {1.0, 3.0, 2.0, 1.0});
  const auto h = tf({1.0}, {1.0, 4.0});
  const auto cl = feedback(g, h);
  Eigen::MatrixXd a(3, 3), b(3, 1), c(1, 3), d(1, 1);  // controllable canonical form of g
  a << 0, 1, 0, 0, 0, 1, -1, -2, -3;
  b << 0, 0, 1;
  c << 1, 2, 0;
  d << 0;
  const auto cl_ss = feedback(ss(a, b, c, d), ss(PlantKind::FirstOrder, 4.0));
  double worst = 0.0;
  for (auto s : random_points(3, 30)) worst = std::max(worst, rel_err(cl_ss(s), cl(s)));
  EXPECT_LT(worst, 1e-13);
}

TEST(StateSpace, BadInputNamesTheMatrix) {
  Eigen::MatrixXd a(2, 2), b(3, 1), c(1, 2), d(1, 1);
  a.setZero();
  b.setZero();
  c.setZero();
  d.setZero();
  try {
    ss(a, b, c, d);
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "B");
  }
  Eigen::MatrixXd b2 = Eigen::MatrixXd::Zero(2, 1);
  a(0, 1) = std::nan("");
  try {
    ss(a, b2, c, d);
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "A");
  }
  Eigen::MatrixXd d1 = Eigen::MatrixXd::Ones(1, 1);
  EXPECT_THROW(feedback(ss(1.0), ss(-1.0), -1), InvalidParameter);  // I + D1 D2 = 0: algebraic loop
  EXPECT_THROW(feedback(ss(1.0), ss(1.0), 0), InvalidParameter);
}
