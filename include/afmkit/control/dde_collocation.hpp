#pragma once
// Chebyshev collocation of the infinitesimal generator (Breda–Maset–Vermiglio) of a linear retarded
// delay-differential system x' = A0 x + Σ_i A_i x(t − τ_i) (loop.hpp: closed_loop_dde()).
// Each delayed matrix is factorised A_i = U_i V_iᵀ (rank r_i, SVD), and only the history of the r_i delayed
// coordinates V_iᵀ x(t + θ), θ ∈ [−τ_i, 0], is discretised on n_i + 1 Chebyshev points: the matrix has size
// d + Σ r_i n_i instead of (n + 1)·d (for the seed-2 loop every r_i = 1). Its eigenvalues approximate the
// characteristic roots; the rightmost ones converge spectrally in n_i (use them as Newton starting points).
#include <complex>
#include <vector>

#include "afmkit/control/loop.hpp"

namespace afmkit::control {

/// Chebyshev differentiation matrix on x_j = cos(πj/n), j = 0..n (Trefethen, Spectral Methods in MATLAB).
Eigen::MatrixXd chebyshev_differentiation(int n);

/// Eigenvalues of the reduced collocation matrix. `nodes` = n per delay (0: automatic from the delay and the
/// frequency scale `frequency_scale`, which should bound |Im| of the roots of interest). Throws
/// InvalidParameter("nodes") if nodes < 0 or > 400.
std::vector<std::complex<double>> collocation_eigenvalues(const DelayDifferentialSystem& system, int nodes = 0,
                                                          double frequency_scale = 1.0);

}  // namespace afmkit::control
