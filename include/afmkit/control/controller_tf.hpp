#pragma once
// Closed-form transfer functions of the seed-2 controllers (seed-2 eqs. 10, 18, 25, 28–31), W = C(s) M, each evaluated
// literally at any complex s. Exactly at a singular point of the literal formula (s = 0, s = ±ikΩ, and for
// (31) the cancelled zeros of 𝒜 − ℬe^{−sT}) the value is taken from the pole-free form
// `controller_response` (loop.hpp), i.e. the limit; exactly at a pole of C the result has infinite magnitude.
// Near such points the literal forms lose digits in proportion to the cancellation they contain (notably
// (31) near s = 0, ±iΩ); `controller_response` does not.
#include <complex>

#include <Eigen/Dense>

#include "afmkit/control/infinite_bank.hpp"
#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/transfer_function.hpp"

namespace afmkit::control {

/// Eq. (10): C(s) = K (a s − bΩ)/(s² + Ω²) (one oscillator, eqs. 5–6).
std::complex<double> single_oscillator_tf(double rotation_frequency, double a, double b, double gain,
                                          std::complex<double> s);
TransferFunction single_oscillator_tf(double rotation_frequency, double a, double b, double gain);

/// Eq. (18), general rejected set R: C = K Σ_{k∈R} H_k / (1 + a0/s + Σ_{k∉R} H_k),
/// H_k = (a_k s − b_k kΩ)/(s² + k²Ω²).
std::complex<double> bank_tf(const OscillatorBank& bank, std::complex<double> s);

/// Eqs. (25)–(27): couplings (20), C = K H1/(1 + H0 + Σ_{k=2}^N H_k), H_k = 2(αs + βΩ)/(s² + k²Ω²), H0 = α/s.
std::complex<double> couplings_tf(double rotation_frequency, int harmonics, double alpha, double beta, double gain,
                                  std::complex<double> s);

/// Eq. (37): 𝓜(s)^{-1} g by Sherman–Morrison, 𝓜 = diag(s − ikΩ) + g wᵀ (eq. 36), w_k = 0 for k ∈ ±R.
/// Entries ordered k = −N..N (index k + N). These are the Laplace transforms H_k/M of η_k (eq. 35).
Eigen::VectorXcd complex_form_states(const OscillatorBank& bank, std::complex<double> s);
/// Eqs. (38)–(39): C = K Σ_{k∈R} (H_k + H_{−k}) with H from complex_form_states.
std::complex<double> complex_form_tf(const OscillatorBank& bank, std::complex<double> s);

/// Eq. (28): C_N through Q_N'(s)/Q_N(s), Q_N(s) = s ∏_{k≤N}(1 + s²/(k²Ω²)) (eq. 23; Q_N and Q_N' by products).
std::complex<double> qn_tf(double rotation_frequency, int harmonics, double alpha, double beta, double gain,
                           std::complex<double> s);

/// Eq. (29) with (30): C∞ = K H1/(1 + (π/Ω)(α + βΩ/s) coth(πs/Ω) − βΩ/s² − H1).
std::complex<double> infinite_tf(const InfiniteBank& bank, std::complex<double> s);
/// Eq. (31): C∞ = 𝒩(s)(1 − e^{−sT})/(𝒜(s) − ℬ(s)e^{−sT}) with the coefficients of infinite_bank.hpp.
std::complex<double> infinite_tf_quasi(const InfiniteBank& bank, std::complex<double> s);

}  // namespace afmkit::control
