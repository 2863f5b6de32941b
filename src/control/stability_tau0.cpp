#include "afmkit/control/stability_tau0.hpp"

#include <cmath>
#include <numbers>

#include <boost/math/tools/toms748_solve.hpp>

#include "afmkit/control/eigenvalues.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

namespace {
void check_couplings(int n, double omega, double alpha, double beta) {
  validate::in_range("harmonics", static_cast<long>(n), 1L, 100000L);
  validate::positive("rotation_frequency", omega);
  validate::finite("alpha", alpha);
  validate::finite("beta", beta);
}
}  // namespace

bool single_oscillator_stable_tau0(double omega, double a, double b, double gain, double rate) {
  validate::positive("rotation_frequency", omega);
  validate::finite("a", a);
  validate::finite("b", b);
  validate::positive("gain", gain);
  validate::positive("plant_rate", rate);
  return a > 0.0 && b < rate * omega / gain;  // (13)
}

Polynomial closed_loop_polynomial(int n, double omega, double alpha, double beta) {
  check_couplings(n, omega, alpha, beta);
  validate::in_range("harmonics", static_cast<long>(n), 1L, 200L);
  std::vector<Polynomial> q(n + 1);
  Polynomial all = Polynomial::constant(1.0);
  for (int k = 1; k <= n; ++k) {
    q[k] = Polynomial({(k * omega) * (k * omega), 0.0, 1.0});
    all = all * q[k];
  }
  Polynomial sum;  // Σ_k P(s)/(s² + k²Ω²)
  for (int k = 1; k <= n; ++k) {
    Polynomial others = Polynomial::constant(1.0);
    for (int j = 1; j <= n; ++j)
      if (j != k) others = others * q[j];
    sum = sum + others;
  }
  const Polynomial s({0.0, 1.0});
  return s * all + alpha * all + 2.0 * (s * Polynomial({beta * omega, alpha}) * sum);  // (22)
}

Polynomial closed_loop_polynomial(const OscillatorBank& bank, double rate) {
  validate::positive("plant_rate", rate);
  const TransferFunction c = tf(bank);  // C = K n/d
  return c.den() + (1.0 / rate) * c.num();
}

NecessaryConditions necessary_conditions(int n, double omega, double alpha, double beta) {
  check_couplings(n, omega, alpha, beta);
  double inv_sq = 0.0;
  for (int k = n; k >= 1; --k) inv_sq += 1.0 / (static_cast<double>(k) * k);
  NecessaryConditions c;
  c.coefficient_2n = (2.0 * n + 1.0) * alpha;                         // (40)
  c.coefficient_1_normalised = 1.0 + 2.0 * beta / omega * inv_sq;     // (41)
  c.alpha_positive = alpha > 0.0;
  c.coefficient_1_positive = c.coefficient_1_normalised > 0.0;
  c.limit_condition = 1.0 + std::numbers::pi * std::numbers::pi / 3.0 * beta / omega > 0.0;  // (42)
  return c;
}

CriticalBeta critical_beta(int n, double omega) {
  validate::in_range("harmonics", static_cast<long>(n), 1L, 10000000L);
  validate::positive("rotation_frequency", omega);
  // x = ν/Ω ∈ (0, 1): g(x) = 1/x + Σ_k 2x/(x² − k²) decreases from +∞ to −∞ (one root).
  auto g = [n](double x) {
    double sum = 0.0;
    for (int k = n; k >= 1; --k) sum += 2.0 * x / (x * x - static_cast<double>(k) * k);
    return 1.0 / x + sum;
  };
  boost::math::tools::eps_tolerance<double> tol(52);
  std::uintmax_t iterations = 200;
  const auto [lo, hi] = boost::math::tools::toms748_solve(g, 1e-9, 1.0 - 1e-9, tol, iterations);
  if (iterations >= 200) throw NumericalFailure("critical_beta: root bracketing did not converge");
  const double x = 0.5 * (lo + hi);
  double sum = 0.0;  // Σ_k 2/(x² − k²)  (= Σ_{0<|k|≤N} Ω/(k(ν − kΩ)) · Ω⁰ in units of Ω)
  for (int k = n; k >= 1; --k) sum += 2.0 / (x * x - static_cast<double>(k) * k);
  return {omega / sum, x * omega};
}

CriticalBeta critical_beta_limit(double omega) {
  validate::positive("rotation_frequency", omega);
  return {-0.25 * omega, 0.5 * omega};
}

bool couplings_stable_tau0(int n, double omega, double alpha, double beta) {
  check_couplings(n, omega, alpha, beta);
  return alpha > 0.0 && beta > critical_beta(n, omega).beta;
}

bool infinite_bank_stable_tau0(double omega, double alpha, double beta) {
  validate::positive("rotation_frequency", omega);
  validate::finite("alpha", alpha);
  validate::finite("beta", beta);
  return alpha > 0.0 && beta > -0.25 * omega;  // (24)
}

std::vector<std::complex<double>> undelayed_poles(const LoopSpec& loop) {
  try {
    return undelayed_poles_secular(loop);
  } catch (const NumericalFailure&) {
    const Bank* inner = nullptr;
    if (const auto* sp = std::get_if<SmithPredictor>(&loop.controller)) inner = &sp->bank;
    const auto* b = inner ? std::get_if<OscillatorBank>(inner) : std::get_if<OscillatorBank>(&loop.controller);
    if (!b || b->harmonics() > 50) throw;
  }
  const Eigen::MatrixXd a = closed_loop_dde(loop).undelayed_matrix();
  const Eigen::VectorXcd ev = eigenvalues(a, "the undelayed closed loop's poles");
  return {ev.data(), ev.data() + ev.size()};
}

double undelayed_spectral_abscissa(const LoopSpec& loop) {
  double m = -INFINITY;
  for (const auto& z : undelayed_poles(loop)) m = std::max(m, z.real());
  return m;
}

std::pair<std::complex<double>, std::complex<double>> root_sensitivity_at_origin(int k) {
  if (k == 0) return {-1.0, 0.0};
  return {-1.0, std::complex<double>(0.0, 1.0 / k)};  // (45)
}

}  // namespace afmkit::control
