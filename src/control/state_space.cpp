#include "afmkit/control/state_space.hpp"

#include <Eigen/LU>
#include <fmt/format.h>

#include "afmkit/control/eigenvalues.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

namespace {
void require_finite(const char* name, const Eigen::MatrixXd& m) {
  if (!m.allFinite()) throw InvalidParameter(name, fmt::format("{}: all entries must be finite numbers", name));
}
void require_shape(bool ok, const char* name, const std::string& msg) {
  if (!ok) throw InvalidParameter(name, fmt::format("{}: {}", name, msg));
}
}  // namespace

StateSpace::StateSpace(Eigen::MatrixXd a, Eigen::MatrixXd b, Eigen::MatrixXd c, Eigen::MatrixXd d)
    : A(std::move(a)), B(std::move(b)), C(std::move(c)), D(std::move(d)) {
  require_shape(A.rows() == A.cols(), "A", fmt::format("must be square, got {}x{}", A.rows(), A.cols()));
  require_shape(B.rows() == A.rows(), "B", fmt::format("must have {} rows (states), got {}", A.rows(), B.rows()));
  require_shape(C.cols() == A.rows(), "C", fmt::format("must have {} columns (states), got {}", A.rows(), C.cols()));
  require_shape(D.rows() == C.rows() && D.cols() == B.cols(), "D",
                fmt::format("must be {}x{} (outputs x inputs), got {}x{}", C.rows(), B.cols(), D.rows(), D.cols()));
  require_shape(D.rows() >= 1 && D.cols() >= 1, "D", "a system needs at least one input and one output");
  require_finite("A", A);
  require_finite("B", B);
  require_finite("C", C);
  require_finite("D", D);
}

Eigen::MatrixXcd StateSpace::evaluate_matrix(std::complex<double> s) const {
  const Eigen::MatrixXcd dc = D.cast<std::complex<double>>();
  if (states() == 0) return dc;
  Eigen::MatrixXcd m = -A.cast<std::complex<double>>();
  m.diagonal().array() += s;
  const Eigen::MatrixXcd x = Eigen::PartialPivLU<Eigen::MatrixXcd>(m).solve(B.cast<std::complex<double>>());
  return C.cast<std::complex<double>>() * x + dc;
}

std::complex<double> StateSpace::operator()(std::complex<double> s) const {
  if (!is_siso())
    throw InvalidParameter("system", fmt::format("system: scalar evaluation needs a SISO system, got {} inputs and "
                                                 "{} outputs", inputs(), outputs()));
  return evaluate_matrix(s)(0, 0);
}

Eigen::VectorXcd StateSpace::poles() const {
  if (states() == 0) return Eigen::VectorXcd(0);
  return eigenvalues(A, "state-space poles");
}

StateSpace ss(Eigen::MatrixXd a, Eigen::MatrixXd b, Eigen::MatrixXd c, Eigen::MatrixXd d) {
  return StateSpace(std::move(a), std::move(b), std::move(c), std::move(d));
}

StateSpace ss(double gain) {
  validate::finite("gain", gain);
  return StateSpace(Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0),
                    Eigen::MatrixXd::Constant(1, 1, gain));
}

StateSpace ss(const OscillatorBank& bank) {
  return StateSpace(bank.state_matrix(), bank.input_vector(), bank.output_vector(), Eigen::MatrixXd::Zero(1, 1));
}

StateSpace ss(PlantKind kind, double rate) {
  validate::positive("plant_rate", rate);
  if (kind == PlantKind::Static) return ss(1.0 / rate);
  return StateSpace(Eigen::MatrixXd::Constant(1, 1, -rate), Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Ones(1, 1),
                    Eigen::MatrixXd::Zero(1, 1));
}

StateSpace series(const StateSpace& g1, const StateSpace& g2) {
  require_shape(g2.inputs() == g1.outputs(), "series",
                fmt::format("sys2 has {} inputs but sys1 has {} outputs", g2.inputs(), g1.outputs()));
  const int n1 = g1.states(), n2 = g2.states();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n1 + n2, n1 + n2);
  a.topLeftCorner(n1, n1) = g1.A;
  a.bottomRightCorner(n2, n2) = g2.A;
  a.bottomLeftCorner(n2, n1) = g2.B * g1.C;
  Eigen::MatrixXd b(n1 + n2, g1.inputs());
  b << g1.B, g2.B * g1.D;
  Eigen::MatrixXd c(g2.outputs(), n1 + n2);
  c << g2.D * g1.C, g2.C;
  return StateSpace(a, b, c, g2.D * g1.D);
}

StateSpace parallel(const StateSpace& g1, const StateSpace& g2) {
  require_shape(g1.inputs() == g2.inputs() && g1.outputs() == g2.outputs(), "parallel",
                "both systems need the same numbers of inputs and outputs");
  const int n1 = g1.states(), n2 = g2.states();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n1 + n2, n1 + n2);
  a.topLeftCorner(n1, n1) = g1.A;
  a.bottomRightCorner(n2, n2) = g2.A;
  Eigen::MatrixXd b(n1 + n2, g1.inputs());
  b << g1.B, g2.B;
  Eigen::MatrixXd c(g1.outputs(), n1 + n2);
  c << g1.C, g2.C;
  return StateSpace(a, b, c, g1.D + g2.D);
}

StateSpace feedback(const StateSpace& g1, const StateSpace& g2, int sign) {
  require_shape(sign == 1 || sign == -1, "feedback", fmt::format("sign = {} must be +1 or -1", sign));
  require_shape(g2.inputs() == g1.outputs() && g2.outputs() == g1.inputs(), "feedback",
                "sys2 must map the outputs of sys1 back to its inputs");
  const int n1 = g1.states(), n2 = g2.states(), p1 = g1.outputs(), m1 = g1.inputs();
  const double sg = sign;
  // y1 = C1 x1 + D1 u1,  u1 = r + sign y2,  y2 = C2 x2 + D2 y1  ⇒  y1 = E (C1 x1 + sign D1 C2 x2 + D1 r)
  const Eigen::MatrixXd i_minus = Eigen::MatrixXd::Identity(p1, p1) - sg * g1.D * g2.D;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(i_minus);
  if (!lu.isInvertible()) throw InvalidParameter("feedback", "feedback: algebraic loop I - sign*D1*D2 is singular");
  const Eigen::MatrixXd e = lu.inverse();
  const Eigen::MatrixXd y_x1 = e * g1.C, y_x2 = sg * e * g1.D * g2.C, y_r = e * g1.D;
  const Eigen::MatrixXd u_x1 = sg * g2.D * y_x1, u_x2 = sg * g2.C + sg * g2.D * y_x2,
                        u_r = Eigen::MatrixXd::Identity(m1, m1) + sg * g2.D * y_r;
  Eigen::MatrixXd a(n1 + n2, n1 + n2);
  a << g1.A + g1.B * u_x1, g1.B * u_x2, g2.B * y_x1, g2.A + g2.B * y_x2;
  Eigen::MatrixXd b(n1 + n2, m1);
  b << g1.B * u_r, g2.B * y_r;
  Eigen::MatrixXd c(p1, n1 + n2);
  c << y_x1, y_x2;
  return StateSpace(a, b, c, y_r);
}

StateSpace feedback(const StateSpace& g1, double gain, int sign) {
  validate::finite("gain", gain);
  require_shape(g1.is_siso(), "feedback", "a scalar feedback gain needs a SISO system");
  return feedback(g1, ss(gain), sign);
}

}  // namespace afmkit::control
