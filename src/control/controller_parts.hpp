#pragma once
// Private to src/control: the pole-free normalised numerator/denominator of a bank controller,
// C(s) = Kn(s)/d(s), with their s-derivatives and a common exponential scale (see loop.hpp for formulas).
#include <complex>

#include "afmkit/control/infinite_bank.hpp"
#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/smith_predictor.hpp"
#include "scaled_dual.hpp"

namespace afmkit::control::detail {

struct BankParts {
  Dual d;           // denominator (curly bracket of eq. 18 times Q_N, or Q∞ (F∞ − H1))
  Dual kn;          // K × numerator
  double ls = 0.0;  // common scale: true values are (d, kn)·e^{ls}
  Scaled scaled_d() const { return {d, ls}; }
  Scaled scaled_kn() const { return {kn, ls}; }
};

/// Finite bank. If a0 = 0 the (then disconnected) integrator x0 is left out: the common factor s is removed.
BankParts bank_parts(const OscillatorBank& bank, cplx s);
/// N = ∞ bank, couplings (20), rejected {1}.
BankParts bank_parts(const InfiniteBank& bank, cplx s);
BankParts bank_parts(const Bank& bank, cplx s);

/// φ(w) = (w cosh w − sinh w)/w² (entire, series near 0) and sinhc(w) = sinh(w)/w, on duals.
Dual phi(Dual w);
Dual sinhc(Dual w);
/// χ(x) = coth x − 1/x (regular at 0, series there).
Dual chi(Dual x);

/// C = kn/d as a plain complex; exactly at a pole (d = 0, kn ≠ 0) returns complex(inf, 0).
cplx ratio(const Dual& num, const Dual& den);

}  // namespace afmkit::control::detail
