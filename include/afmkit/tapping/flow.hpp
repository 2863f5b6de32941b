#pragma once
// Closed-form flow of one linear mode of the tapping cantilever with a piecewise-linear law (seed-1 eqs. 10,
// 11, 26): between events the motion obeys the constant-coefficient ODE
//   ẍ + c ẋ + k x = Γ cos(ωt) + f,      c = 2ξω_n,  k = ω_n² + K,  f = −(F + K l)
// (K, F = stiffness and offset of the active branch; K = F = 0 out of contact). Its solution is
//   y(t0 + τ) = y_p(t0 + τ) + E(τ) (y0 − y_p(t0)),   y = (x, ẋ),
//   y_p(t) = (f/k + Re[Z e^{iωt}], Re[iωZ e^{iωt}]),  Z = Γ / (k − ω² + i c ω)   (particular response)
//   E(τ) = e^{Aτ} = e^{−ατ} [C(τ) I + S(τ) (A + α I)],  A = [[0, 1], [−k, −c]],  α = c/2,
//   C = cosh(√D τ), S = sinh(√D τ)/√D,  D = α² − k  (entire in D: covers under-, critically and over-damped).
// The state-transition matrix E(τ) is also the sensitivity ∂y/∂y0, and ∂y/∂l = ∂(f/k)/∂l · (e₁ − E(τ) e₁).
#include <complex>

#include <Eigen/Core>

namespace afmkit::tapping {

class LinearModeFlow {
 public:
  LinearModeFlow() = default;
  /// damping c ≥ 0, stiffness k > 0, drive Γ cos ωt, constant force f; offset_slope = ∂(f/k)/∂l.
  LinearModeFlow(double damping, double stiffness, double drive_amplitude, double drive_frequency, double force,
                 double offset_slope);

  /// Particular (steady harmonic) response at absolute time t, and its value with precomputed cos/sin(ωt).
  Eigen::Vector2d particular(double t) const;
  /// Homogeneous propagator E(τ).
  Eigen::Matrix2d propagator(double tau) const;
  /// State at t0 + τ from y0 at t0.
  Eigen::Vector2d state(double t0, const Eigen::Vector2d& y0, double tau) const;
  /// State when the particular response at t0 (p0) is already known: cheaper for repeated evaluation.
  Eigen::Vector2d state(const Eigen::Vector2d& homogeneous0, double t, double tau) const {
    return particular(t) + propagator(tau) * homogeneous0;
  }
  /// ∂y(t0 + τ)/∂l for a fixed y0.
  Eigen::Vector2d separation_sensitivity(double tau) const;
  /// Same, from the propagator E(τ) already evaluated.
  Eigen::Vector2d separation_sensitivity(const Eigen::Matrix2d& propagator) const {
    return offset_slope_ * Eigen::Vector2d(1.0 - propagator(0, 0), -propagator(1, 0));
  }

  /// Upper bound of |x_h(t0+τ)| for τ ≥ 0 given the homogeneous part h0 at t0 (for skipping guard scans).
  double homogeneous_bound(const Eigen::Vector2d& homogeneous0) const;
  double static_offset() const { return offset_; }         // f/k
  double harmonic_amplitude() const { return std::abs(z_); }  // |Z|
  double decay_rate() const { return alpha_; }              // α = c/2 (|E| ≤ const·e^{−(α−√D)τ})
  /// Shortest oscillation period present (2π/√(−D) if underdamped, else +inf) — for scan step bounds.
  double mode_period() const;
  double discriminant() const { return disc_; }  // D = α² − k
  double stiffness() const { return stiffness_; }  // k
  double damping() const { return damping_; }      // c
  double force() const { return force_; }          // f
  double drive_amplitude() const { return gamma_; }  // Γ
  double drive_frequency() const { return omega_; }  // ω
  std::complex<double> harmonic() const { return z_; }  // Z
  bool underdamped() const { return disc_ < 0; }
  double damped_frequency() const { return disc_ < 0 ? root_ : 0.0; }  // √(−D)
  /// Bound of |dⁿx/dtⁿ| for τ ≥ 0 (underdamped modes only, else +inf): ωⁿ|Z| + ρ kⁿᐟ², ρ = homogeneous amplitude
  /// (each derivative of e^{(−α ± i√−D)τ} multiplies its modulus by √k). Used for safe guard-scan steps.
  double derivative_bound(const Eigen::Vector2d& homogeneous0, int order) const;

 private:
  double damping_ = 0, stiffness_ = 1, gamma_ = 0, omega_ = 1, force_ = 0, offset_slope_ = 0;
  double alpha_ = 0, disc_ = -1, root_ = 1, offset_ = 0;
  std::complex<double> z_;
};

}  // namespace afmkit::tapping
