// The Sader–Jarvis force integral (Sader & Jarvis, APL 84, 1801 (2004), eq. (9)) with Ω linear between the
// measured points and every kernel integrated exactly, the square-root singularity at t = z included.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "afmkit/spectroscopy/reconstruct_kernels.hpp"

namespace afmkit::spectroscopy {

std::vector<std::vector<double>> sader_jarvis_forces(const std::vector<double>& t,
                                                     const std::vector<std::vector<double>>& omegas,
                                                     const std::vector<double>& amplitude, double spring_constant,
                                                     SaderJarvisTerms terms, const ExponentialTail& tail) {
  const std::size_t n = t.size(), m = omegas.size();
  const double inv_sqrt_pi = 1.0 / std::sqrt(std::numbers::pi);
  const double inv_sqrt2 = 1.0 / std::numbers::sqrt2;
  // G = A^{3/2} Ω: the quantity differentiated when the amplitude is inside the derivative
  std::vector<double> a32(n);
  for (std::size_t i = 0; i < n; ++i) a32[i] = amplitude[i] * std::sqrt(amplitude[i]);
  std::vector<std::vector<double>> g(m, std::vector<double>(n));
  for (std::size_t k = 0; k < m; ++k)
    for (std::size_t i = 0; i < n; ++i) g[k][i] = a32[i] * omegas[k][i];
  std::vector<std::vector<double>> force(m, std::vector<double>(n, 0.0));
  std::vector<double> sum(m);
  for (std::size_t j = 0; j < n; ++j) {
    std::fill(sum.begin(), sum.end(), 0.0);
    for (std::size_t i = j; i + 1 < n; ++i) {
      // the interval's geometry, shared by every Ω
      const double h = t[i + 1] - t[i];
      const double ua = t[i] - t[j], ub = t[i + 1] - t[j];
      const double ra = std::sqrt(ua), rb = std::sqrt(ub);
      const double d_sqrt = h / (ra + rb);                     // √ub − √ua, without cancellation
      const double d_32 = h * (ub + ra * rb + ua) / (ra + rb);  // ub^{3/2} − ua^{3/2}
      const double a_mid = 0.5 * (amplitude[i] + amplitude[i + 1]);
      const double sqrt_a_mid = std::sqrt(a_mid);
      for (std::size_t k = 0; k < m; ++k) {
        const std::vector<double>& omega = omegas[k];
        const double s = (omega[i + 1] - omega[i]) / h;  // dΩ/dt on the interval
        if (terms.small_amplitude_terms) {
          const double int_omega = 0.5 * (omega[i] + omega[i + 1]) * h;  // ∫ Ω dt (exact for linear Ω)
          // ∫ Ω/√(t − z) dt with Ω = Ω_i + s (u − ua), u = t − z
          const double int_omega_sqrt = omega[i] * 2.0 * d_sqrt + s * ((2.0 / 3.0) * d_32 - 2.0 * ua * d_sqrt);
          sum[k] += int_omega + sqrt_a_mid * inv_sqrt_pi / 8.0 * int_omega_sqrt;
        }
        // ∫ (1/√(2(t − z))) d(A^{3/2}Ω)/dt dt with the derivative constant on the interval
        const double derivative =
            terms.amplitude_inside_derivative ? (g[k][i + 1] - g[k][i]) / h : a_mid * sqrt_a_mid * s;
        sum[k] -= inv_sqrt2 * derivative * 2.0 * d_sqrt;
      }
    }
    if (tail.active) {
      // Ω = a e^{−(t − t_N)/λ} beyond t_N, A = A_N: closed forms with s = t_N − z_j
      const double a = tail.value, lambda = tail.decay_length, s = t.back() - t[j];
      const double i2 = a * std::sqrt(std::numbers::pi * lambda) * erfcx(std::sqrt(s / lambda));  // ∫ Ω/√(t − z)
      const double i3 = -i2 / lambda;                                                          // ∫ Ω'/√(t − z)
      for (std::size_t k = 0; k < m; ++k) {
        if (terms.small_amplitude_terms) sum[k] += a * lambda + std::sqrt(amplitude.back()) * inv_sqrt_pi / 8.0 * i2;
        sum[k] -= inv_sqrt2 * a32.back() * i3;
      }
    }
    for (std::size_t k = 0; k < m; ++k) force[k][j] = 2.0 * spring_constant * sum[k];
  }
  return force;
}

std::vector<double> sader_jarvis_force(const std::vector<double>& t, const std::vector<double>& omega,
                                       const std::vector<double>& amplitude, double spring_constant,
                                       SaderJarvisTerms terms, const ExponentialTail& tail) {
  return sader_jarvis_forces(t, {omega}, amplitude, spring_constant, terms, tail).front();
}

}  // namespace afmkit::spectroscopy
