#pragma once
// Time discretisation of the seed-2 controller and plant (docs/theory-control.md#simulation):
//   * exact zero-order hold (ZOH) of an LTI system via the exponential of the augmented matrix,
//   * φ-functions, used to integrate the first-order plant (seed-2 eq. 1) exactly over a step when its input is a
//     polynomial in time,
//   * the stability region of the 3rd-order Adams–Bashforth method (AB3) that the paper uses for the controller.
#include <complex>

#include <Eigen/Dense>

namespace afmkit::control {

/// How a sampled controller (real-time filter, simulation) is discretised at the sampling instants.
///   ZeroOrderHold      — exact: the whole controller ż = A z + b m with the sample m_n held over the step
///                        (Φ = e^{Ah}); the rejected oscillator keeps its poles e^{±iΩh}, so the first harmonic of
///                        the samples is removed exactly; the kept harmonics 0, 2..N pass with an O(h²) error
///                        (zeros of a sampled system are not mapped exactly).
///   BlockZeroOrderHold — the block scheme of Fig. 6 (eqs. 25–27) sampled: each oscillator is exact for the held
///                        error e_n = m_n − c_eᵀ z_n (rotation by kΩh plus a rank-1 coupling through e), the
///                        coupling loop is closed at the sampling instants. Both the rejection of harmonic 1 and the
///                        pass-through of harmonics 0, 2..N are exact in the samples; the loop dynamics deviate
///                        from the continuous design by O(h) (e is held over the step: about half a sample of extra delay in the
///                        coupling loop).
enum class SampledForm { ZeroOrderHold, BlockZeroOrderHold };

/// Exact ZOH of ż = A z + B v with v held constant over each step h:
///   z_{n+1} = Φ z_n + Γ v_n,   Φ = e^{Ah},   Γ = ∫₀ʰ e^{As} ds · B,
/// both read off exp([[A, B], [0, 0]] h) (Van Loan). Throws InvalidParameter for h ≤ 0 or a size mismatch.
struct ZeroOrderHold {
  Eigen::MatrixXd transition;  // Φ
  Eigen::MatrixXd input;       // Γ (one column per input)
};
ZeroOrderHold zero_order_hold(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double step);

/// φ_k(z) = Σ_{m≥0} z^m/(m+k)!  (φ_0 = e^z, φ_1 = (e^z − 1)/z, φ_{k+1} = (φ_k − 1/k!)/z), k = 0..8, accurate for
/// every z (series near 0, recurrence elsewhere). ∫₀ʰ e^{λ(h−s)} s^j ds = j! h^{j+1} φ_{j+1}(λh).
double phi_function(int k, double z);
std::complex<double> phi_function(int k, std::complex<double> z);

/// 3rd-order Adams–Bashforth: z_{n+1} = z_n + h (23 d_n − 16 d_{n−1} + 5 d_{n−2})/12, d = ż.
/// Applied to ż = λz it gives ζ³ − ζ² − w (23ζ² − 16ζ + 5)/12 = 0 with w = hλ; the method is stable for the
/// mode iff every root satisfies |ζ| ≤ 1 (root condition).
namespace ab3 {
/// Largest root modulus max|ζ| for w = hλ.
double amplification(std::complex<double> w);
/// amplification(w) ≤ 1 (+ rounding tolerance).
bool is_stable(std::complex<double> w);
/// Boundary locus w(θ) = (ζ³ − ζ²)·12/(23ζ² − 16ζ + 5), ζ = e^{iθ}.
std::complex<double> boundary(double theta);
/// Where the boundary crosses the negative real axis: −6/11 (θ = π).
double real_axis_limit();
/// Where the boundary crosses the positive imaginary axis (≈ 0.7236), found by root-finding on Re w(θ) = 0.
double imaginary_axis_limit();
/// Smallest number of steps per `period` (h = period/steps) that puts hλ inside the region for every λ
/// (bisection along h; returns 1 if every λ is 0).
long minimum_steps(const Eigen::VectorXcd& eigenvalues, double period);
}  // namespace ab3

}  // namespace afmkit::control
