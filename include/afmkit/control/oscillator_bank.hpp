#pragma once
// The harmonic-rejection controller of seed 2 (eqs. 5–20, docs/theory-control.md#oscillator-bank): a zero-frequency
// integrator x0 and N harmonic oscillators (x_k, z_k) at kΩ, driven by the measured signal m(t) = y(t − τ) from which
// the
// reconstructed *kept* harmonics are subtracted:
//   e  = m − x0 − Σ_{k kept} x_k                                   (square bracket of eq. 15)
//   ẋ0 = a0 e,   ẋ_k = −kΩ z_k + a_k e,   ż_k = kΩ x_k + b_k e        (eq. 15)
//   u  = −K Σ_{k rejected} x_k                                      (eq. 6; rejected = {1} in the paper)
// Conventions (docs/conventions.md): negative feedback U(s) = −C(s) M(s); K = γ̂ (estimate of the plant rate γ) is
// the design rule; couplings (20): a0 = α, a_k = 2α, b_k = −2β/k.
// State ordering: (x0, x1, z1, x2, z2, …, xN, zN) ∈ ℝ^{2N+1}.
#include <complex>
#include <vector>

#include <Eigen/Dense>

namespace afmkit::control {

class OscillatorBank {
 public:
  /// General couplings. `a` and `b` have N entries (k = 1..N); `rejected` lists the harmonics (1..N)
  /// whose oscillators drive the output (default {1}). Validated: Ω > 0, N ≥ 1, finite couplings,
  /// K > 0 finite, rejected non-empty, within 1..N, no duplicates.
  OscillatorBank(double rotation_frequency, double a0, std::vector<double> a, std::vector<double> b, double gain,
                 std::vector<int> rejected = {1});
  /// The couplings (20): a0 = α, a_k = 2α, b_k = −2β/k (α, β in rad/s, like Ω).
  static OscillatorBank with_couplings(double rotation_frequency, int harmonics, double alpha, double beta,
                                       double gain, std::vector<int> rejected = {1});
  /// The single oscillator of eqs. (5)–(6): N = 1, no integrator (a0 = 0), couplings a, b.
  static OscillatorBank single(double rotation_frequency, double a, double b, double gain);

  double rotation_frequency() const { return omega_; }  // Ω
  int harmonics() const { return static_cast<int>(a_.size()); }  // N
  double a0() const { return a0_; }
  double a(int k) const { return a_.at(k - 1); }
  double b(int k) const { return b_.at(k - 1); }
  double gain() const { return gain_; }  // K
  const std::vector<int>& rejected() const& { return rejected_; }
  const std::vector<int>& rejected() const&& = delete;
  bool is_rejected(int k) const;
  int state_size() const { return 2 * harmonics() + 1; }

  /// State-space matrices of the controller from m to w = −u = K Σ_rej x_k: ż = A z + B m, w = C z.
  /// A = A0 − b c_eᵀ (docs/theory-control.md#oscillator-bank). Dense (2N+1)×(2N+1).
  Eigen::MatrixXd state_matrix() const;
  Eigen::VectorXd input_vector() const;   // b = (a0, a1, b1, …)
  Eigen::RowVectorXd output_vector() const;  // K c_rᵀ
  Eigen::RowVectorXd error_vector() const;   // c_eᵀ (e = m − c_eᵀ z)

  OscillatorBank with_gain(double gain) const;

 private:
  double omega_, a0_, gain_;
  std::vector<double> a_, b_;
  std::vector<int> rejected_;
  std::vector<char> rejected_mask_;  // index k (0..N)
};

/// Eigenvalues of state_matrix() without forming it: ±ikΩ for each rejected k (exact), and the roots of the
/// bank's denominator d(s) (loop.hpp) by the Aberth–Ehrlich iteration from ikΩ − g_k (eq. 34), O(N) per
/// evaluation, O(N²) in total. Throws NumericalFailure if the iteration does not converge.
std::vector<std::complex<double>> bank_eigenvalues(const OscillatorBank& bank);

}  // namespace afmkit::control
