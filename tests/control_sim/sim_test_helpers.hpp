#pragma once
// Independent reference computations for the control_sim tests: adaptive Runge–Kutta (Boost.Odeint
// Dormand–Prince 5(4)) integration of linear systems, and a Newton solver for the one-oscillator characteristic
// quasi-polynomial (seed-2 eq. 12, docs/theory-control.md#delay-margin).
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <Eigen/Dense>
#include <boost/numeric/odeint.hpp>

namespace afmkit::control::simref {

/// z(h) for ż = A z + B v (v constant) from z0, by adaptive RK with tight tolerances.
inline Eigen::VectorXd integrate_linear(const Eigen::MatrixXd& a, const Eigen::VectorXd& bv, Eigen::VectorXd z0,
                                        double h) {
  namespace odeint = boost::numeric::odeint;
  std::vector<double> z(z0.data(), z0.data() + z0.size());
  auto rhs = [&](const std::vector<double>& x, std::vector<double>& dx, double) {
    const Eigen::Map<const Eigen::VectorXd> xm(x.data(), static_cast<Eigen::Index>(x.size()));
    Eigen::Map<Eigen::VectorXd> dm(dx.data(), static_cast<Eigen::Index>(dx.size()));
    dm = a * xm + bv;
  };
  odeint::integrate_adaptive(odeint::make_controlled<odeint::runge_kutta_dopri5<std::vector<double>>>(1e-14, 1e-14),
                             rhs, z, 0.0, h, h / 50.0);
  return Eigen::Map<Eigen::VectorXd>(z.data(), z0.size());
}

/// Rightmost root near `guess` of s² + Ω² + ρ e^{−sτ}(a s − bΩ) = 0 (seed-2 eq. 12) by Newton.
inline std::complex<double> one_oscillator_root(double omega, double a, double b, double rho, double tau,
                                                std::complex<double> guess) {
  std::complex<double> s = guess;
  for (int it = 0; it < 100; ++it) {
    const std::complex<double> e = std::exp(-s * tau);
    const std::complex<double> g = s * s + omega * omega + rho * e * (a * s - b * omega);
    const std::complex<double> dg = 2.0 * s + rho * e * (a - tau * (a * s - b * omega));
    const std::complex<double> ds = g / dg;
    s -= ds;
    if (std::abs(ds) < 1e-15 * (1.0 + std::abs(s))) break;
  }
  return s;
}

/// Critical delay of eq. (12) (seed-2 ext. E1) and the crossing frequency ν, for b = 0:
/// ν⁴ − (2Ω² + ρ²a²)ν² + Ω⁴ = 0, e^{−iντ} = (ν² − Ω²)/(ρ i a ν); smallest positive τ over both roots ν².
inline std::pair<double, double> one_oscillator_critical_delay(double omega, double a, double rho) {
  const double p = 2.0 * omega * omega + rho * rho * a * a;
  const double disc = std::sqrt(p * p - 4.0 * std::pow(omega, 4));
  std::pair<double, double> best{1e300, 0.0};
  for (double nu2 : {0.5 * (p + disc), 0.5 * (p - disc)}) {
    const double nu = std::sqrt(nu2);
    const std::complex<double> rhs = (nu2 - omega * omega) / (rho * std::complex<double>(0.0, a * nu));
    double tau = -std::arg(rhs) / nu;
    while (tau < 0) tau += 2.0 * std::numbers::pi / nu;
    if (tau < best.first) best = {tau, nu};
  }
  return best;
}

}  // namespace afmkit::control::simref
