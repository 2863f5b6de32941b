#include "afmkit/control/eigenvalues.hpp"

#include <string>

#include <Eigen/Eigenvalues>

#include "afmkit/core/error.hpp"

namespace afmkit::control {

Eigen::VectorXcd eigenvalues(const Eigen::MatrixXd& m, std::string_view what) {
  if (m.rows() == 0) return Eigen::VectorXcd(0);
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(m, false);
  if (solver.info() != Eigen::Success)
    throw NumericalFailure(std::string(what) + ": the eigenvalue solver (real Schur QR iteration) did not converge");
  return solver.eigenvalues();
}

}  // namespace afmkit::control
