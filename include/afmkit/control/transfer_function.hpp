#pragma once
// Rational transfer functions with real coefficients (python-control's `tf`), polynomials, and the exact
// rational form of the seed-2 controllers and plants (seed-2 eqs. 10, 18). Rational forms of a bank have
// coefficients up to ∏k²Ω² and are well conditioned for moderate N only (≲ 15); for any N use the pole-free
// evaluations of loop.hpp (`controller_response`) or controller_tf.hpp.
#include <complex>
#include <vector>

#include "afmkit/control/oscillator_bank.hpp"
#include "afmkit/control/plant.hpp"

namespace afmkit::control {

/// p(s) = Σ_j c_j s^j, real coefficients stored in ASCENDING powers; trailing (highest-power) zeros trimmed.
class Polynomial {
 public:
  Polynomial() = default;                                  // the zero polynomial
  explicit Polynomial(std::vector<double> ascending);      // validated finite ("coefficients")
  static Polynomial from_descending(std::vector<double> descending);  // numpy / python-control order
  static Polynomial monomial(int degree, double coefficient = 1.0);
  static Polynomial constant(double c) { return Polynomial({c}); }
  static Polynomial from_roots(const std::vector<std::complex<double>>& roots);  // conjugate pairs required

  int degree() const { return static_cast<int>(c_.size()) - 1; }  // −1 for the zero polynomial
  bool is_zero() const { return c_.empty(); }
  double coefficient(int power) const;  // 0 beyond the degree
  const std::vector<double>& ascending() const& { return c_; }
  std::vector<double> ascending() const&& { return c_; }
  std::vector<double> descending() const;
  double leading() const;

  std::complex<double> operator()(std::complex<double> s) const;  // Horner
  Polynomial derivative() const;
  /// Complex roots: eigenvalues of the balanced companion matrix (as numpy.roots).
  std::vector<std::complex<double>> roots() const;

  friend Polynomial operator+(const Polynomial& a, const Polynomial& b);
  friend Polynomial operator-(const Polynomial& a, const Polynomial& b);
  friend Polynomial operator*(const Polynomial& a, const Polynomial& b);
  friend Polynomial operator*(double k, const Polynomial& a);

 private:
  void trim();
  std::vector<double> c_;
};

class TransferFunction {
 public:
  /// Validated: denominator not the zero polynomial ("den").
  TransferFunction(Polynomial num, Polynomial den);
  const Polynomial& num() const& { return num_; }
  Polynomial num() const&& { return num_; }
  const Polynomial& den() const& { return den_; }
  Polynomial den() const&& { return den_; }

  /// num(s)/den(s); exactly at a pole (den = 0, num ≠ 0) returns complex(inf, 0).
  std::complex<double> operator()(std::complex<double> s) const;
  std::vector<std::complex<double>> poles() const { return den_.roots(); }
  std::vector<std::complex<double>> zeros() const { return num_.roots(); }
  bool is_proper() const { return num_.degree() <= den_.degree(); }

  friend TransferFunction operator*(const TransferFunction& a, const TransferFunction& b);
  friend TransferFunction operator+(const TransferFunction& a, const TransferFunction& b);
  friend TransferFunction operator-(const TransferFunction& a, const TransferFunction& b);
  friend TransferFunction operator/(const TransferFunction& a, const TransferFunction& b);
  friend TransferFunction operator*(double k, const TransferFunction& a);

 private:
  Polynomial num_, den_;
};

/// python-control convention: coefficients in DESCENDING powers, tf([1], [1, 2]) = 1/(s + 2).
TransferFunction tf(std::vector<double> num_descending, std::vector<double> den_descending);
TransferFunction tf(Polynomial num, Polynomial den);
/// G1 (1 − sign G1 G2)^{-1} as in python-control (sign = −1: negative feedback): num1 den2 / (den1 den2 − sign num1 num2).
TransferFunction feedback(const TransferFunction& sys1, const TransferFunction& sys2, int sign = -1);
TransferFunction feedback(const TransferFunction& sys1, double gain = 1.0, int sign = -1);

/// Exact rational C(s) = W/M of a finite bank (eq. 18, general rejected set): numerator
/// K Σ_{k∈R} s(a_k s − b_k kΩ) ∏_{j≠k}(s² + j²Ω²), denominator (s + a0) ∏(s² + k²Ω²) + Σ_{k∉R} s(a_k s − b_k kΩ) ∏_{j≠k};
/// both divided by s when a0 = 0 (no integrator). The denominator is det(sI − A) of the realisation.
TransferFunction tf(const OscillatorBank& bank);
/// Delay-free plant P0: 1/γ (static, eq. 9 without delay) or 1/(s + γ) (first order).
TransferFunction tf(PlantKind kind, double plant_rate);

}  // namespace afmkit::control
