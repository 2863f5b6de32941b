// The DOP853 stepper of the adaptive tapping integrator (src/tapping/sim/dop853.hpp, private) against the closed
// form of a forced undamped oscillator x'' + ω0² x = Γ cos ωt:
//   x(t) = (x0 − G) cos ω0 t + G cos ωt,  G = Γ/(ω0² − ω²)   (x(0) = x0, ẋ(0) = 0).
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "../../src/tapping/sim/dop853.hpp"

namespace {

constexpr double w0 = 1.3, w = 0.7, gamma_drive = 0.4, x0 = 1.0;
constexpr double g = gamma_drive / (w0 * w0 - w * w);

struct Forced {
  void operator()(const std::array<double, 2>& y, std::array<double, 2>& dy, double t) const {
    dy[0] = y[1];
    dy[1] = -w0 * w0 * y[0] + gamma_drive * std::cos(w * t);
  }
};

std::array<double, 2> exact(double t) {
  return {(x0 - g) * std::cos(w0 * t) + g * std::cos(w * t), -(x0 - g) * w0 * std::sin(w0 * t) - g * w * std::sin(w * t)};
}

using afmkit::tapping::detail::Dop853;

TEST(Dop853, StepsAndDenseOutputFollowTheClosedFormToTheTolerance) {
  Dop853<Forced, 2> stepper(1e-13, 1e-12, 0.5);
  stepper.initialize(Forced{}, {x0, 0.0}, 0.0, 0.01);
  const double t_end = 20.0;
  int steps = 0;
  double worst_step = 0.0, worst_dense = 0.0;
  while (stepper.current_time() < t_end) {
    const auto [t_old, t_new] = stepper.do_step(t_end);
    ++steps;
    ASSERT_LE(t_new, t_end);
    const auto e = exact(t_new);
    worst_step = std::max({worst_step, std::abs(stepper.current_state()[0] - e[0]),
                           std::abs(stepper.current_state()[1] - e[1])});
    for (int k = 1; k < 8; ++k) {
      const double t = t_old + (t_new - t_old) * k / 8.0;
      std::array<double, 2> y{};
      stepper.calc_state(t, y);
      const auto ye = exact(t);
      worst_dense = std::max({worst_dense, std::abs(y[0] - ye[0]), std::abs(y[1] - ye[1])});
    }
  }
  EXPECT_EQ(stepper.current_time(), t_end);  // the last step lands on the limit
  EXPECT_LT(worst_step, 1e-10);
  EXPECT_LT(worst_dense, 1e-10);
  // order 8: ~3 periods at 1e-12 in a few dozen steps (a 5th-order method needs several hundred)
  EXPECT_LT(steps, 150);
}

TEST(Dop853, ErrorFallsWithTheTolerance) {
  auto error_at = [](double tol) {
    Dop853<Forced, 2> stepper(0.1 * tol, tol, 1.0);
    stepper.initialize(Forced{}, {x0, 0.0}, 0.0, 0.01);
    while (stepper.current_time() < 10.0) stepper.do_step(10.0);
    return std::abs(stepper.current_state()[0] - exact(10.0)[0]);
  };
  const double coarse = error_at(1e-6), fine = error_at(1e-10);
  EXPECT_LT(fine, 1e-8);
  EXPECT_LT(fine, 1e-2 * coarse);
}

TEST(Dop853, StepSizeUnderflowIsANumericalFailureNotAHang) {
  struct Blowup {
    void operator()(const std::array<double, 2>& y, std::array<double, 2>& dy, double) const {
      dy[0] = y[0] * y[0] * 1e6;  // finite-time blow-up at t = 1e-6
      dy[1] = 0.0;
    }
  };
  Dop853<Blowup, 2> stepper(1e-12, 1e-12, 1.0);
  stepper.initialize(Blowup{}, {1.0, 0.0}, 0.0, 1e-3);
  EXPECT_THROW(
      {
        for (int i = 0; i < 100000; ++i) stepper.do_step(1.0);
      },
      afmkit::NumericalFailure);
}

}  // namespace
