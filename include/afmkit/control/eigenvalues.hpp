#pragma once
// The eigenvalues of a real square matrix (Eigen's real Schur method), in one translation unit: every caller
// shares one instantiation of Eigen::EigenSolver (compiling it costs ≈ 11 s per source file).
#include <string_view>

#include <Eigen/Core>

namespace afmkit::control {

/// Eigenvalues of the real square matrix `m` (no eigenvectors), in Eigen's order. Throws NumericalFailure naming
/// `what` when the QR iteration does not converge.
Eigen::VectorXcd eigenvalues(const Eigen::MatrixXd& m, std::string_view what);

}  // namespace afmkit::control
