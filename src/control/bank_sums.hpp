#pragma once
// Private to src/control: the O(N) sums over a bank's oscillators (eq. 18) and the O(N) Aberth sums, in real
// arithmetic over contiguous arrays so that the loops vectorise (one SIMD reduction each). Used by the delay-free
// poles and bank eigenvalues (secular_roots.cpp) and by the fast characteristic function (spectra/).
#include <complex>
#include <cstddef>
#include <vector>

#include "afmkit/control/oscillator_bank.hpp"

namespace afmkit::control::detail {

/// One set of harmonics k: a_k, b_k kΩ and k²Ω².
struct BankArrays {
  std::vector<double> a, bkw, kw2;
};

/// A bank split into the harmonics that feed D (kept) and N (rejected), plus 1/(k²Ω²) of all of them (for the
/// normaliser Q = [s] Π (1 + s²/(k²Ω²)) of loop.hpp).
struct SplitBank {
  double a0 = 0.0;
  BankArrays kept, rejected;
  std::vector<double> inv_kw2;
};
SplitBank split_bank(const OscillatorBank& bank);

/// Σ G_k, Σ a_k v_k, Σ G_k v_k and Σ v_k with v_k = 1/(s² + k²Ω²), G_k = (a_k s − b_k kΩ) v_k; then
/// Σ G_k' = Σ a_k v_k − 2s Σ G_k v_k and Σ d/ds log(1 + s²/(k²Ω²)) = 2s Σ v_k.
struct BankSums {
  std::complex<double> g, a_inv, g_inv, inv;
};
BankSums bank_sums(const BankArrays& terms, std::complex<double> s);

/// q Π_k (1 + s² inv_kw2_k), rescaled by powers of two (2^∓500) whenever it leaves [1e-150, 1e150]: a common
/// positive factor of Δ and Δ' (only phases and ratios are used); checked every 4 factors (exact for |s| < 1e6 Ω).
std::complex<double> normaliser_product(const std::vector<double>& inv_kw2, std::complex<double> s2,
                                        std::complex<double> q);

/// Σ_k 1/(z − (re_k + i im_k)) over n points (the Aberth correction).
std::complex<double> inverse_distance_sum(const double* re, const double* im, std::size_t n, std::complex<double> z);

}  // namespace afmkit::control::detail
