// The modal zero-order hold of the bank (O(N) per step) against the dense exact ZOH of the state-space form
// (matrix exponential of the augmented matrix, Van Loan; discretisation.hpp) and against AB3 at large N.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Dense>

#include "afmkit/control/closed_loop_simulation.hpp"
#include "afmkit/control/discretisation.hpp"
#include "../../src/control/sim/controller_steppers.hpp"

using namespace afmkit::control;

TEST(ModalZoh, MatchesDenseZeroOrderHold) {
  for (const auto& rejected : {std::vector<int>{1}, std::vector<int>{1, 3}}) {
    const auto bank = OscillatorBank::with_couplings(1.0, 6, 0.15, -0.08, 7.0, rejected);
    const double h = 2.0 * 3.141592653589793 / 97.0;
    const ZeroOrderHold dense = zero_order_hold(bank.state_matrix(), bank.input_vector(), h);
    const Eigen::RowVectorXd c = -bank.output_vector();
    Eigen::VectorXd z = Eigen::VectorXd::Zero(bank.state_size());
    detail::BankZoh modal(bank, h);
    double worst = 0.0, scale = 0.0;
    for (int n = 0; n < 400; ++n) {
      const double m = std::sin(0.37 * n) + 0.3 * std::cos(1.3 * n) + 0.1;
      const double u_dense = c.dot(z);
      worst = std::max(worst, std::abs(modal.output() - u_dense));
      scale = std::max(scale, std::abs(u_dense));
      modal.step(m, nullptr);
      z = dense.transition * z + dense.input.col(0) * m;
    }
    EXPECT_LT(worst, 1e-10 * scale);
  }
}

TEST(ModalZoh, LargeBankSimulationRejectsFirstHarmonic) {
  // N = 300: zoh and ab3 both converge to the same steady state (seed-2 eq. 16 target); zoh is O(N) per step
  const auto bank = OscillatorBank::with_couplings(1.0, 300, 0.3, -0.1, 20.0);
  const Plant plant(PlantKind::Static, 20.0, 1.0, 0.1 * 2.0 * 3.141592653589793, Disturbance::paper_example(1));
  SimulationOptions o;
  o.periods = 30;
  o.steps_per_period = 2000;
  o.record_every = 0;
  o.stepping = ControllerStepping::ZeroOrderHold;
  const auto r = ClosedLoopSimulation(plant, Bank(bank), o).run().report;
  EXPECT_FALSE(r.diverged);
  EXPECT_LT(r.residual_first_harmonic, 1e-6);
}
