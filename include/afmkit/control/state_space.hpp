#pragma once
// A small LTI toolbox (names as in python-control): state-space value type `StateSpace` / `ss`,
// evaluation G(s) = C (sI − A)^{-1} B + D at any complex s, `series`, `parallel`, `feedback`.
// Realisations of the seed-2 controller and plant (seed-2 eqs. 1, 3, 15) are provided as `ss(...)` overloads.
#include <complex>

#include <Eigen/Dense>

#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/plant.hpp"

namespace afmkit::control {

struct StateSpace {
  Eigen::MatrixXd A, B, C, D;

  /// Validated: A square n×n, B n×m, C p×n, D p×m, all entries finite (InvalidParameter "A"/"B"/"C"/"D").
  StateSpace(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D);

  int states() const { return static_cast<int>(A.rows()); }
  int inputs() const { return static_cast<int>(B.cols()); }
  int outputs() const { return static_cast<int>(C.rows()); }
  bool is_siso() const { return inputs() == 1 && outputs() == 1; }

  /// G(s) = C (sI − A)^{-1} B + D (complex partial-pivot LU). At an eigenvalue of A the LU is singular and
  /// the entries are ±inf/NaN.
  Eigen::MatrixXcd evaluate_matrix(std::complex<double> s) const;
  /// SISO value G(s); throws InvalidParameter("system") if not SISO.
  std::complex<double> operator()(std::complex<double> s) const;
  /// Eigenvalues of A.
  Eigen::VectorXcd poles() const;
};

StateSpace ss(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D);
/// Static gain D (no states).
StateSpace ss(double gain);
/// The controller from m to w = −u (W = C M): A = A0 − b c_eᵀ, B = b, C = K c_rᵀ, D = 0
/// (docs/theory-control.md#oscillator-bank). Includes x0 even when a0 = 0 (then x0 is an uncontrollable mode at s = 0).
StateSpace ss(const OscillatorBank& bank);
/// Delay-free plant from u to y: static 1/γ (D only) or first order ẏ = −γ y + u (eq. 1 with f = 0).
StateSpace ss(PlantKind kind, double plant_rate);

/// sys2 ∘ sys1 (output of sys1 feeds sys2): G = G2 G1.
StateSpace series(const StateSpace& sys1, const StateSpace& sys2);
/// G = G1 + G2.
StateSpace parallel(const StateSpace& sys1, const StateSpace& sys2);
/// Closed loop y = G1 (r + sign·G2 y), python-control's feedback(sys1, sys2, sign) (sign = −1: negative
/// feedback): G = G1 (I − sign G2 G1)^{-1}. Throws InvalidParameter("feedback") if the loop is algebraically
/// singular (I − sign D1 D2 not invertible) or dimensions do not match.
StateSpace feedback(const StateSpace& sys1, const StateSpace& sys2, int sign = -1);
StateSpace feedback(const StateSpace& sys1, double gain = 1.0, int sign = -1);

}  // namespace afmkit::control
