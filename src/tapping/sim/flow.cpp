#include "afmkit/tapping/flow.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "afmkit/core/validate.hpp"

namespace afmkit::tapping {

LinearModeFlow::LinearModeFlow(double damping, double stiffness, double drive_amplitude, double drive_frequency,
                               double force, double offset_slope)
    : damping_(validate::non_negative("damping", damping)),
      stiffness_(validate::positive("stiffness", stiffness)),
      gamma_(validate::finite("drive_amplitude", drive_amplitude)),
      omega_(validate::positive("drive_frequency", drive_frequency)),
      force_(validate::finite("force", force)),
      offset_slope_(validate::finite("offset_slope", offset_slope)) {
  alpha_ = 0.5 * damping_;
  disc_ = alpha_ * alpha_ - stiffness_;
  root_ = std::sqrt(std::abs(disc_));
  offset_ = force_ / stiffness_;
  z_ = gamma_ / std::complex<double>(stiffness_ - omega_ * omega_, damping_ * omega_);
}

Eigen::Vector2d LinearModeFlow::particular(double t) const {
  const double c = std::cos(omega_ * t), s = std::sin(omega_ * t);
  // Z e^{iωt} = (zr c − zi s) + i (zr s + zi c)
  const double re = z_.real() * c - z_.imag() * s;
  const double im = z_.real() * s + z_.imag() * c;
  return {offset_ + re, -omega_ * im};
}

Eigen::Matrix2d LinearModeFlow::propagator(double tau) const {
  // e^{Aτ} = e^{−ατ}[C I + S (A + αI)], C = cosh(√D τ), S = sinh(√D τ)/√D (D = α² − k)
  double ec, es;  // e^{−ατ} C, e^{−ατ} S
  const double u = disc_ * tau * tau;
  if (std::abs(u) < 0.25) {
    // entire series in u: C = Σ u^n/(2n)!, S = τ Σ u^n/(2n+1)!
    double c = 1.0, s = 1.0, term_c = 1.0, term_s = 1.0;
    for (int n = 1; n <= 12; ++n) {
      term_c *= u / ((2.0 * n - 1.0) * (2.0 * n));
      term_s *= u / ((2.0 * n) * (2.0 * n + 1.0));
      c += term_c;
      s += term_s;
    }
    const double e = std::exp(-alpha_ * tau);
    ec = e * c;
    es = e * s * tau;
  } else if (disc_ < 0) {
    const double e = std::exp(-alpha_ * tau);
    ec = e * std::cos(root_ * tau);
    es = e * std::sin(root_ * tau) / root_;
  } else {
    const double ep = std::exp((root_ - alpha_) * tau), em = std::exp(-(root_ + alpha_) * tau);
    ec = 0.5 * (ep + em);
    es = 0.5 * (ep - em) / root_;
  }
  Eigen::Matrix2d m;
  m << ec + es * alpha_, es, -es * stiffness_, ec - es * alpha_;
  return m;
}

Eigen::Vector2d LinearModeFlow::state(double t0, const Eigen::Vector2d& y0, double tau) const {
  return particular(t0 + tau) + propagator(tau) * (y0 - particular(t0));
}

Eigen::Vector2d LinearModeFlow::separation_sensitivity(double tau) const {
  const Eigen::Matrix2d e = propagator(tau);
  return offset_slope_ * Eigen::Vector2d(1.0 - e(0, 0), -e(1, 0));
}

double LinearModeFlow::homogeneous_bound(const Eigen::Vector2d& h0) const {
  // x_h(τ) = e^{−ατ}[C h_x + S (α h_x + h_v)]
  const double b = alpha_ * h0.x() + h0.y();
  if (disc_ < 0) return std::hypot(h0.x(), b / root_);  // e^{−ατ}·R cos(…)
  // over/critically damped: e^{−ατ}cosh ≤ 1, e^{−ατ} sinh(rτ)/r ≤ τ e^{−(α−r)τ} ≤ 1/(e (α − r))
  const double gap = alpha_ - root_;
  const double smax = gap > 0 ? 1.0 / (std::numbers::e * gap) : std::numeric_limits<double>::infinity();
  return std::abs(h0.x()) + std::abs(b) * smax;
}

double LinearModeFlow::derivative_bound(const Eigen::Vector2d& h0, int order) const {
  if (!(disc_ < 0)) return std::numeric_limits<double>::infinity();
  double w = 1.0, k = 1.0;
  for (int i = 0; i < order; ++i) w *= omega_, k *= stiffness_;
  return w * std::abs(z_) + homogeneous_bound(h0) * std::sqrt(k);
}

double LinearModeFlow::mode_period() const {
  return disc_ < 0 ? 2.0 * std::numbers::pi / root_ : std::numeric_limits<double>::infinity();
}

}  // namespace afmkit::tapping
