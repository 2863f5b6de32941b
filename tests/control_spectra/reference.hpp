#pragma once
// Independent references for the spectra tests:
//  * full-state Chebyshev collocation of the infinitesimal generator (Breda–Maset–Vermiglio, the algorithm of
//    the independent check in docs/theory-control.md#delay-margin) on delay-differential matrices assembled here from
//    the controller's state-space matrices (OscillatorBank::state_matrix etc.), not from loop.hpp's characteristic
//    function;
//  * the neutral quasi-polynomial γ(𝒜 − ℬe^{−sT}) + e^{−sτ}𝒩(1 − e^{−sT}) from the InfiniteBank coefficients.
#include <complex>
#include <numbers>
#include <vector>

#include <Eigen/Dense>

#include "afmkit/control/infinite_bank.hpp"
#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/plant.hpp"

namespace afmkit::test {

using cplx = std::complex<double>;

/// x' = A0 x + A1 x(t − τ) for a bank with the static (y = u/γ) or first-order (y' = −γy + u) plant.
/// The integrator x0 is left out when a0 = 0 (it is then disconnected).
inline void loop_matrices(const control::OscillatorBank& bank, control::PlantKind kind, double gamma, Eigen::MatrixXd& a0,
                          Eigen::MatrixXd& a1) {
  const int off = bank.a0() == 0.0 ? 1 : 0;
  const int nz = bank.state_size() - off;
  const Eigen::MatrixXd a = bank.state_matrix().bottomRightCorner(nz, nz);
  const Eigen::VectorXd b = bank.input_vector().tail(nz);
  const Eigen::RowVectorXd c = bank.output_vector().tail(nz);  // w = c z, u = −w
  if (kind == control::PlantKind::Static) {
    a0 = a;
    a1 = -(1.0 / gamma) * b * c;  // m(t) = y(t − τ) = −c z(t − τ)/γ
    return;
  }
  const int n = nz + 1;
  a0 = Eigen::MatrixXd::Zero(n, n);
  a0.topLeftCorner(nz, nz) = a;
  a0(nz, nz) = -gamma;
  a0.row(nz).head(nz) = -c;
  a1 = Eigen::MatrixXd::Zero(n, n);
  a1.col(nz).head(nz) = b;  // m(t) = y(t − τ)
}

/// Full-state Chebyshev collocation (n + 1 nodes) of z' = A0 z + A1 z(t − τ); τ = 0: eig(A0 + A1).
inline std::vector<cplx> collocation_reference(const Eigen::MatrixXd& a0, const Eigen::MatrixXd& a1, double tau, int n) {
  const int d = static_cast<int>(a0.rows());
  if (tau == 0.0) {
    Eigen::EigenSolver<Eigen::MatrixXd> es(a0 + a1, false);
    return {es.eigenvalues().data(), es.eigenvalues().data() + d};
  }
  Eigen::VectorXd x(n + 1), c(n + 1);
  for (int j = 0; j <= n; ++j) {
    x(j) = std::cos(std::numbers::pi * j / n);
    c(j) = ((j == 0 || j == n) ? 2.0 : 1.0) * ((j % 2) ? -1.0 : 1.0);
  }
  Eigen::MatrixXd dm = Eigen::MatrixXd::Zero(n + 1, n + 1);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      if (i != j) dm(i, j) = c(i) / c(j) / (x(i) - x(j));
  for (int i = 0; i <= n; ++i) dm(i, i) = -dm.row(i).sum();
  dm *= 2.0 / tau;
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero((n + 1) * d, (n + 1) * d);
  m.block(0, 0, d, d) = a0;
  m.block(0, n * d, d, d) = a1;
  for (int i = 1; i <= n; ++i)
    for (int j = 0; j <= n; ++j) m.block(i * d, j * d, d, d) = dm(i, j) * Eigen::MatrixXd::Identity(d, d);
  Eigen::EigenSolver<Eigen::MatrixXd> es(m, false);
  return {es.eigenvalues().data(), es.eigenvalues().data() + (n + 1) * d};
}

inline std::vector<cplx> reference_roots(const control::OscillatorBank& bank, control::PlantKind kind, double gamma,
                                         double tau, int n = 48) {
  Eigen::MatrixXd a0, a1;
  loop_matrices(bank, kind, gamma, a0, a1);
  return collocation_reference(a0, a1, tau, n);
}

/// Neutral quasi-polynomial of the realisation (32)–(33) (static plant) and its derivative (central difference).
inline cplx neutral_quasi_polynomial(const control::InfiniteBank& bank, double gamma, double tau, cplx s) {
  const auto a = bank.a_coefficients(), b = bank.b_coefficients();
  const auto n = bank.n_coefficients();
  cplx pa = 0.0, pb = 0.0, pn = 0.0;
  for (int j = 4; j >= 0; --j) {
    pa = pa * s + a[j];
    pb = pb * s + b[j];
  }
  for (int j = 3; j >= 0; --j) pn = pn * s + n[j];
  const cplx z = std::exp(-s * bank.period());
  return gamma * (pa - pb * z) + std::exp(-s * tau) * pn * (1.0 - z);
}

/// Nearest distance from s to the set.
inline double distance(const std::vector<cplx>& set, cplx s) {
  double d = INFINITY;
  for (const cplx& t : set) d = std::min(d, std::abs(t - s));
  return d;
}

}  // namespace afmkit::test
