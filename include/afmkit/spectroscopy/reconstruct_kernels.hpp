#pragma once
// The numerical kernels shared by the force reconstructions (docs/reconstruction.md): the Sader–Jarvis integral
// with its square-root singularity integrated analytically, the long-range tail, noise estimates and the monotone
// (isotonic) fit used for the dissipation. SI units throughout (m, N, Hz, J); Ω = Δf/f0 is dimensionless.
#include <functional>
#include <vector>

namespace afmkit::spectroscopy {

/// The long-range tail of a curve beyond its last point t_N: y(t) = value · exp(−(t − t_N)/decay_length) for t > t_N
/// (active), or 0 (inactive: the integrals end at the last point).
struct ExponentialTail {
  bool active = false;
  double value = 0.0;         ///< y at t_N (the last measured value: the tail is continuous there)
  double decay_length = 0.0;  ///< λ [m] > 0
};

/// Fits ln|y| = c − (t − t_N)/λ by least squares to the last max(5, n/10) points (all of one sign, decaying). Returns
/// an inactive tail when they do not decay (λ not positive and finite), when they change sign or hold a zero.
ExponentialTail fit_exponential_tail(const std::vector<double>& t, const std::vector<double>& y);

/// The terms of the Sader–Jarvis integral (Sader & Jarvis, APL 84, 1801 (2004), eq. (9)) that a method keeps:
///   F(z) = 2k ∫_z^∞ [ Ω(t) + (A^{1/2} / (8 √(π (t − z)))) Ω(t) − (1/√(2 (t − z))) d(A^{3/2} Ω)/dt ] dt
/// With constant A this is eq. (9) itself. `amplitude_inside_derivative` = false puts the local A^{3/2} in front of
/// dΩ/dt instead (the amplitude taken at t); `small_amplitude_terms` = false drops the first two terms (the
/// large-amplitude limit, an Abel inversion).
struct SaderJarvisTerms {
  bool small_amplitude_terms = true;
  bool amplitude_inside_derivative = false;
};

/// F(z_j) [N] at every point of the curve: Ω (= Δf/f0) linear between the points (so dΩ/dt constant on each
/// interval) and every kernel integrated exactly over each interval, the 1/√(t − z) singularity at t = z included
/// (no finite-difference derivative, no excluded first interval). `amplitude` [m] per point (constant for FM),
/// `t` strictly ascending [m]. The tail adds its closed-form integrals (erfcx).
std::vector<double> sader_jarvis_force(const std::vector<double>& t, const std::vector<double>& omega,
                                       const std::vector<double>& amplitude, double spring_constant,
                                       SaderJarvisTerms terms, const ExponentialTail& tail);
/// The same for several Ω on one grid (the noise realisations): the intervals' geometry (square roots, divisions)
/// computed once for all; each result is what sader_jarvis_force gives for that Ω.
std::vector<std::vector<double>> sader_jarvis_forces(const std::vector<double>& t,
                                                     const std::vector<std::vector<double>>& omegas,
                                                     const std::vector<double>& amplitude, double spring_constant,
                                                     SaderJarvisTerms terms, const ExponentialTail& tail);

/// Matrix method (Giessibl, APL 78, 123 (2001)): solves the discretised first-order frequency-shift integral
///   Ω(z_i) = −(1/(π k A)) ∫_{−1}^{1} F(z_i + A(1 + u)) u/√(1 − u²) du
/// for F at the nodes, F linear between the nodes (hat functions, weights in closed form), F = 0 at and beyond the
/// last node: an upper-triangular system solved by back substitution. Several right-hand sides at once (each a
/// vector of Ω at the nodes); returns F [N] per right-hand side.
std::vector<std::vector<double>> matrix_method_force(const std::vector<double>& t,
                                                     const std::vector<std::vector<double>>& omegas, double amplitude,
                                                     double spring_constant);

/// The first-order large-amplitude frequency shift (Giessibl 2001) of the force F at closest distance z:
///   Δf(z) = −(f0/(π k A)) ∫_{−1}^{1} F(z + A(1 + u)) u/√(1 − u²) du,
/// by adaptive Gauss–Kronrod quadrature in θ (u = −cos θ), split at `breaks` (distances where F is not smooth).
double forward_frequency_shift(const std::function<double(double)>& force, double z, double spring_constant, double resonance_frequency,
                               double amplitude, const std::vector<double>& breaks);

/// The white-noise standard deviation of samples y (robust: 1.4826 · median |second difference| / √6); 0 for
/// fewer than 5 points.
double estimate_noise(const std::vector<double>& y);

/// The non-increasing sequence nearest to y in least squares (pool-adjacent-violators).
std::vector<double> isotonic_nonincreasing(const std::vector<double>& y);

/// e^{x²} erfc(x) for x ≥ 0 without overflow.
double erfcx(double x);

}  // namespace afmkit::spectroscopy
