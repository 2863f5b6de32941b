#include "afmkit/control/transfer_function.hpp"

#include <algorithm>
#include <limits>

#include <fmt/format.h>

#include "afmkit/control/eigenvalues.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

// ---------------------------------------------------------------- Polynomial
namespace {
// Parlett–Reinsch balancing with radix-2 scalings (as LAPACK dgebal), in place. Eigen's PolynomialSolver
// lost roots of the badly scaled p_N (N = 15) that this recovers to ~1e-8.
void balance(Eigen::MatrixXd& a) {
  const auto n = a.rows();
  bool done = false;
  while (!done) {
    done = true;
    for (Eigen::Index i = 0; i < n; ++i) {
      double c = 0.0, r = 0.0;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (j == i) continue;
        c += std::abs(a(j, i));
        r += std::abs(a(i, j));
      }
      if (c == 0.0 || r == 0.0) continue;
      const double s = c + r;
      double f = 1.0, g = r / 2.0;
      while (c < g) {
        f *= 2.0;
        c *= 4.0;
      }
      g = r * 2.0;
      while (c > g) {
        f /= 2.0;
        c /= 4.0;
      }
      if ((c + r) / f < 0.95 * s) {
        done = false;
        a.row(i) /= f;
        a.col(i) *= f;
      }
    }
  }
}
}  // namespace

Polynomial::Polynomial(std::vector<double> ascending) : c_(std::move(ascending)) {
  for (double x : c_)
    if (!std::isfinite(x)) throw InvalidParameter("coefficients", "coefficients: all must be finite numbers");
  trim();
}

Polynomial Polynomial::from_descending(std::vector<double> d) {
  std::reverse(d.begin(), d.end());
  return Polynomial(std::move(d));
}

Polynomial Polynomial::monomial(int degree, double coefficient) {
  validate::in_range("degree", static_cast<long>(degree), 0L, 1000000L);
  std::vector<double> c(degree + 1, 0.0);
  c[degree] = coefficient;
  return Polynomial(std::move(c));
}

Polynomial Polynomial::from_roots(const std::vector<std::complex<double>>& roots) {
  Polynomial p = constant(1.0);
  std::vector<bool> used(roots.size(), false);
  for (std::size_t i = 0; i < roots.size(); ++i) {
    if (used[i]) continue;
    used[i] = true;
    const auto r = roots[i];
    if (r.imag() == 0.0) {
      p = p * Polynomial({-r.real(), 1.0});
      continue;
    }
    std::size_t j = i + 1;
    while (j < roots.size() && (used[j] || roots[j] != std::conj(r))) ++j;
    if (j == roots.size()) throw InvalidParameter("roots", "roots: complex roots must come in conjugate pairs");
    used[j] = true;
    p = p * Polynomial({std::norm(r), -2.0 * r.real(), 1.0});
  }
  return p;
}

void Polynomial::trim() {
  while (!c_.empty() && c_.back() == 0.0) c_.pop_back();
}

double Polynomial::coefficient(int power) const {
  return power >= 0 && power < static_cast<int>(c_.size()) ? c_[power] : 0.0;
}

std::vector<double> Polynomial::descending() const { return {c_.rbegin(), c_.rend()}; }

double Polynomial::leading() const { return c_.empty() ? 0.0 : c_.back(); }

std::complex<double> Polynomial::operator()(std::complex<double> s) const {
  std::complex<double> v = 0.0;
  for (auto it = c_.rbegin(); it != c_.rend(); ++it) v = v * s + *it;
  return v;
}

Polynomial Polynomial::derivative() const {
  if (c_.size() <= 1) return {};
  std::vector<double> d(c_.size() - 1);
  for (std::size_t j = 1; j < c_.size(); ++j) d[j - 1] = j * c_[j];
  return Polynomial(std::move(d));
}

std::vector<std::complex<double>> Polynomial::roots() const {
  if (degree() < 1) return {};
  // zero roots are split off (the companion solver needs a nonzero constant term for good balancing)
  std::size_t lead0 = 0;
  while (c_[lead0] == 0.0) ++lead0;
  std::vector<std::complex<double>> out(lead0, 0.0);
  const int n = degree() - static_cast<int>(lead0);
  if (n >= 1) {
    Eigen::VectorXd c(n + 1);
    for (int j = 0; j <= n; ++j) c(j) = c_[lead0 + j];
    if (n == 1) {
      out.emplace_back(-c(0) / c(1));
    } else {
      // companion matrix (last column = −c_j/c_n), Parlett–Reinsch balancing, real Schur eigenvalues
      Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);
      for (int i = 1; i < n; ++i) m(i, i - 1) = 1.0;
      for (int i = 0; i < n; ++i) m(i, n - 1) = -c(i) / c(n);
      balance(m);
      const Eigen::VectorXcd ev = eigenvalues(m, "polynomial roots (companion matrix)");
      for (int j = 0; j < n; ++j) out.push_back(ev(j));
    }
  }
  return out;
}

Polynomial operator+(const Polynomial& a, const Polynomial& b) {
  std::vector<double> c(std::max(a.c_.size(), b.c_.size()), 0.0);
  for (std::size_t j = 0; j < a.c_.size(); ++j) c[j] += a.c_[j];
  for (std::size_t j = 0; j < b.c_.size(); ++j) c[j] += b.c_[j];
  return Polynomial(std::move(c));
}
Polynomial operator-(const Polynomial& a, const Polynomial& b) { return a + (-1.0) * b; }
Polynomial operator*(const Polynomial& a, const Polynomial& b) {
  if (a.is_zero() || b.is_zero()) return {};
  std::vector<double> c(a.c_.size() + b.c_.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.c_.size(); ++i)
    for (std::size_t j = 0; j < b.c_.size(); ++j) c[i + j] += a.c_[i] * b.c_[j];
  return Polynomial(std::move(c));
}
Polynomial operator*(double k, const Polynomial& a) {
  std::vector<double> c = a.c_;
  for (double& x : c) x *= k;
  return Polynomial(std::move(c));
}

// ---------------------------------------------------------------- TransferFunction
TransferFunction::TransferFunction(Polynomial num, Polynomial den) : num_(std::move(num)), den_(std::move(den)) {
  if (den_.is_zero()) throw InvalidParameter("den", "den: the denominator must not be the zero polynomial");
}

std::complex<double> TransferFunction::operator()(std::complex<double> s) const {
  const auto d = den_(s), n = num_(s);
  if (d == 0.0) {
    if (n == 0.0) return {std::numeric_limits<double>::quiet_NaN(), 0.0};
    return {std::numeric_limits<double>::infinity(), 0.0};
  }
  return n / d;
}

TransferFunction operator*(const TransferFunction& a, const TransferFunction& b) {
  return {a.num_ * b.num_, a.den_ * b.den_};
}
TransferFunction operator+(const TransferFunction& a, const TransferFunction& b) {
  return {a.num_ * b.den_ + b.num_ * a.den_, a.den_ * b.den_};
}
TransferFunction operator-(const TransferFunction& a, const TransferFunction& b) { return a + (-1.0) * b; }
TransferFunction operator/(const TransferFunction& a, const TransferFunction& b) {
  if (b.num_.is_zero()) throw InvalidParameter("divisor", "divisor: division by the zero transfer function");
  return {a.num_ * b.den_, a.den_ * b.num_};
}
TransferFunction operator*(double k, const TransferFunction& a) { return {k * a.num_, a.den_}; }

TransferFunction tf(std::vector<double> num, std::vector<double> den) {
  return {Polynomial::from_descending(std::move(num)), Polynomial::from_descending(std::move(den))};
}
TransferFunction tf(Polynomial num, Polynomial den) { return {std::move(num), std::move(den)}; }

TransferFunction feedback(const TransferFunction& g1, const TransferFunction& g2, int sign) {
  if (sign != 1 && sign != -1) throw InvalidParameter("feedback", fmt::format("feedback: sign = {} must be +1 or -1", sign));
  return {g1.num() * g2.den(), g1.den() * g2.den() - static_cast<double>(sign) * (g1.num() * g2.num())};
}
TransferFunction feedback(const TransferFunction& g1, double gain, int sign) {
  validate::finite("gain", gain);
  return feedback(g1, TransferFunction(Polynomial::constant(gain), Polynomial::constant(1.0)), sign);
}

TransferFunction tf(const OscillatorBank& bank) {
  const int n = bank.harmonics();
  const double w = bank.rotation_frequency();
  const bool no_integrator = bank.a0() == 0.0;
  std::vector<Polynomial> q(n + 1);
  Polynomial all = Polynomial::constant(1.0);
  for (int k = 1; k <= n; ++k) {
    q[k] = Polynomial({(k * w) * (k * w), 0.0, 1.0});
    all = all * q[k];
  }
  Polynomial num, den = no_integrator ? all : Polynomial({bank.a0(), 1.0}) * all;
  for (int k = 1; k <= n; ++k) {
    Polynomial others = Polynomial::constant(1.0);
    for (int j = 1; j <= n; ++j)
      if (j != k) others = others * q[j];
    // s(a_k s − b_k kΩ), or (a_k s − b_k kΩ) without the integrator
    const Polynomial lk = no_integrator ? Polynomial({-bank.b(k) * k * w, bank.a(k)})
                                        : Polynomial({0.0, -bank.b(k) * k * w, bank.a(k)});
    if (bank.is_rejected(k)) num = num + lk * others;
    else den = den + lk * others;
  }
  return {bank.gain() * num, den};
}

TransferFunction tf(PlantKind kind, double rate) {
  validate::positive("plant_rate", rate);
  if (kind == PlantKind::Static) return tf({1.0}, {rate});
  return tf({1.0}, {1.0, rate});
}

}  // namespace afmkit::control
