#pragma once
// Private to src/control/spectra: a fast evaluator of the meromorphic characteristic function
//   f(s) = c_D(s) D(s) + c_N(s) N(s) = Δ(s)/Q(s)
// (C = K N/D; Q = Q_N or Q∞ the pole-free normaliser of loop.hpp, so f has the zeros of Δ and poles only at
// the controller's oscillator frequencies on the imaginary axis) and its derivative, in plain double complex
// arithmetic without scaling. Used for Newton tracking of the rightmost roots in charts and tuning (Newton on f
// and on Δ converge to the same roots); the certified counts use Δ of loop.hpp.
//   plain loop  c_D = M,     c_N = ρ e^{−sτ}                                   (ρ = K/γ; M = 1 or 1 + s/γ)
//   Smith       c_D = M M̂,   c_N = (K/γ̂) M (1 − e^{−sτ_c}) + ρ M̂ e^{−s(τ_m+τ)}
//   finite bank D = 1 + a0/s + Σ_{k∉R} G_k,  N = Σ_{k∈R} G_k,  G_k = (a_k s − b_k kΩ)/(s² + k²Ω²)   (eq. 18)
//   N = ∞       D = 1 + (π/Ω)(α + βΩ/s) coth(πs/Ω) − βΩ/s² − H1,  N = H1 = 2(αs + βΩ)/(s² + Ω²)  (eq. 29)
#include <complex>
#include <vector>

#include "afmkit/control/loop.hpp"
#include "../bank_sums.hpp"

namespace afmkit::control::spectra_detail {

class FastCharacteristic {
 public:
  explicit FastCharacteristic(const LoopSpec& loop);
  /// f and f' at s (non-finite exactly at a pole of f).
  void evaluate(std::complex<double> s, std::complex<double>& f, std::complex<double>& df) const;
  /// Newton step Δ/Δ' = 1/(Q'/Q + f'/f) of the entire Δ = Q f (robust next to the poles of f).
  std::complex<double> newton_step(std::complex<double> s) const;
  /// The entire Δ = Q f and Δ' (Q = [s] Π_k (1 + s²/(k²Ω²)) or (Ω/π) sinh(πs/Ω)); same zeros and scale as
  /// characteristic() of loop.hpp while the partial products of Q stay within [1e-150, 1e150]; beyond (large N,
  /// |s| ≫ Ω) both are scaled by a common power of two (phases and ratios exact: all the callers need). May be
  /// non-finite exactly at a pole of f or where sinh overflows (N = ∞).
  void entire(std::complex<double> s, std::complex<double>& delta, std::complex<double>& ddelta) const;
  /// Δ/Q at s = iν split as X + Y e^{−iντ} (τ the loop delay): X, Y independent of τ (delay_margin.hpp).
  void crossing_parts(double nu, std::complex<double>& x, std::complex<double>& y) const;
  double rotation_frequency() const { return omega_; }

 private:
  /// D, D', N, N', Q'/Q and (if `q` is not null) Q at s.
  void bank(std::complex<double> s, std::complex<double>& d, std::complex<double>& dd, std::complex<double>& n,
            std::complex<double>& dn, std::complex<double>& log_dq, std::complex<double>* q) const;
  void evaluate(std::complex<double> s, std::complex<double>& f, std::complex<double>& df,
                std::complex<double>& log_dq, std::complex<double>* q) const;
  double omega_;
  bool infinite_ = false;
  detail::SplitBank bank_;  // finite bank: kept (D) and rejected (N) harmonics

  double alpha_ = 0.0, beta_ = 0.0;  // N = ∞
  // loop
  bool first_order_ = false, smith_ = false, model_first_order_ = false;
  double rate_ = 1.0, model_rate_ = 1.0, rho_ = 1.0, k_over_model_ = 0.0;
  double delay_ = 0.0, measurement_delay_ = 0.0, correction_delay_ = 0.0;
};

}  // namespace afmkit::control::spectra_detail
