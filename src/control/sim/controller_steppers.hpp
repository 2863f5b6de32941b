#pragma once
// Internal: fixed-step controllers of the closed-loop simulation (closed_loop_simulation.cpp).
// Each stepper holds the state at t_n, gives u_n = output(), and step(m_n, poly) advances to t_{n+1} while
// describing u over [t_n, t_{n+1}] as a cubic u(t_n + s) = c0 + c1 s + c2 s² + c3 s³ (for the exact plant step).
// No allocation in step().
#include <array>
#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "afmkit/control/infinite_bank.hpp"
#include "afmkit/control/oscillator_bank.hpp"

namespace afmkit::control::detail {

using OutputPolynomial = std::array<double, 4>;

/// Finite bank (eq. 15, 6) stepped by AB3 (AB1, AB2 on the first two steps), dense output for u.
class BankAb3 {
 public:
  BankAb3(const OscillatorBank& bank, double step);
  double output() const;
  void step(double measured, OutputPolynomial* poly);
  const Eigen::VectorXd& state() const { return z_; }

 private:
  void derivative(double measured, Eigen::VectorXd& d) const;
  int harmonics_;
  double h_, gain_, a0_;
  Eigen::VectorXd freq_, a_, b_, kept_;  // per oscillator k = 1..N (index k−1): kΩ, a_k, b_k, 1 if x_k enters e
  std::vector<int> rejected_index_;      // state index 2k−1 of each rejected oscillator
  Eigen::VectorXd z_;
  std::array<Eigen::VectorXd, 3> d_;     // derivative history (ring)
  int cur_ = 0;
  long count_ = 0;
};

/// Finite bank discretised exactly for a held sample (ZOH) in modal coordinates; u held. With the eigenvalues
/// λ_j of A (bank_eigenvalues) the modes are q_j' = λ_j q_j + β_j m, u = Re Σ_j o_j q_j, stepped exactly:
/// q_j ← e^{λ_j h} q_j + β_j (e^{λ_j h} − 1)/λ_j m. O(N) per step and O(N²) set-up, no N×N matrix:
///   kept-subsystem modes (D(λ_j) = 0, D the curly bracket of eq. 18): β_j = 1/D'(λ_j), o_j = −K N(λ_j)
///   (the residues of −C = −K N/D), N = Σ_rejected G_k;
///   rejected oscillator r at λ = ±ik_rΩ: β = (a_r ± i b_r)/(2 D(λ)), o = −K.
class BankZoh {
 public:
  BankZoh(const OscillatorBank& bank, double step);
  double output() const;
  void step(double measured, OutputPolynomial* poly);

 private:
  std::vector<std::complex<double>> decay_, input_, out_, q_;
};

/// Finite bank, block scheme sampled: e_n = m_n − c_eᵀ z_n held, each oscillator advanced by its own exact ZOH
/// (2×2 matrix exponential per oscillator), u held.
class BankBlockZoh {
 public:
  BankBlockZoh(const OscillatorBank& bank, double step);
  double output() const { return c_.dot(z_); }
  void step(double measured, OutputPolynomial* poly);

 private:
  std::vector<Eigen::Matrix2d> rot_;
  std::vector<Eigen::Vector2d> in_;
  double g0_;
  Eigen::VectorXd z_;
  Eigen::RowVectorXd c_, ce_;
};

/// N = ∞ controller, neutral realisation (32)–(33) (docs/theory-control.md#neutral-realisation), AB3 on ξ, delay lines
/// of one period (M steps) that read 0 before the controller has run one period (Heaviside rule).
class NeutralAb3 {
 public:
  NeutralAb3(const InfiniteBank& bank, int steps_per_period, double step);
  double output() const { return -w_; }
  void step(double measured, OutputPolynomial* poly);

 private:
  double delayed(const std::vector<double>& buf, long index) const {
    return index >= 0 ? buf[static_cast<std::size_t>(index) & mask_] : 0.0;
  }
  std::array<double, 5> a_, b_;
  std::array<double, 4> n_;
  int period_steps_;
  double h_;
  std::array<double, 4> xi_{};
  std::array<std::array<double, 4>, 3> d_{};
  int cur_ = 0;
  long count_ = 0;
  double w_ = 0.0;  // w_n
  std::vector<double> wbuf_, mbuf_;
  std::size_t mask_;
};

/// AB3 (or AB1/AB2 at start) coefficients for `count` previous steps, and the dense-output polynomial of one
/// component: x(t_n + s) − x_n = s d0 + s² c2 + s³ c3 given d0 = d_n, d1 = d_{n−1}, d2 = d_{n−2}.
struct AbCoefficients {
  double beta0, beta1, beta2;
};
inline AbCoefficients ab_coefficients(long count) {
  if (count == 0) return {1.0, 0.0, 0.0};         // Euler
  if (count == 1) return {1.5, -0.5, 0.0};        // AB2
  return {23.0 / 12.0, -16.0 / 12.0, 5.0 / 12.0};  // AB3
}
inline std::array<double, 3> ab_dense(long count, double h, double d0, double d1, double d2) {
  // Integral of the backward-difference interpolant p(σ) = d0 + (σ/h)∇ + (σ/h)(σ/h + 1)/2 ∇² over [0, s].
  if (count == 0) return {d0, 0.0, 0.0};
  const double nabla = d0 - d1;
  if (count == 1) return {d0, nabla / (2.0 * h), 0.0};
  const double nabla2 = d0 - 2.0 * d1 + d2;
  return {d0, nabla / (2.0 * h) + nabla2 / (4.0 * h), nabla2 / (6.0 * h * h)};
}

}  // namespace afmkit::control::detail
