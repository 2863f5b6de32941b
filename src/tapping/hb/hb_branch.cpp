#include "afmkit/tapping/hb_branch.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/describing_functions.hpp"

namespace afmkit::tapping {

namespace {

using std::numbers::pi;  // (a using-declaration: repeatable in a unity build)

// A point of the q-axis with the bar functions and their derivatives in the curve parameter θ.
struct Location {
  double q;
  double gap;          // 1 − q
  double angle;        // contact angle (π for q ≤ −1)
  double dq;           // dq/dθ
  BarFunctions bar;
  BarFunctions dbar;   // d/dθ
};

Location contact_location(const ContactBarFunctions& b, double gap) {
  // θ = a: q = cos a, dq/da = −sin a.
  return {1.0 - gap, gap, b.angle, -b.sine, b.value, b.angle_derivative};
}

// Both roots of (E1) at one location (shared work done once); slopes only when with_slope.
HbRoots evaluate(const HbCoefficients& c, const Location& at, bool with_slope) {
  HbRoots out;
  for (HbBranchEvaluation* r : {&out.plus, &out.minus}) {
    r->q = at.q;
    r->gap = at.gap;
    r->contact_angle = at.angle;
  }
  const auto& law = c.law;
  const double sum_k = law.approach_stiffness + law.departure_stiffness;  // Σ_K
  const double sum_f = law.approach_adhesion + law.departure_adhesion;    // Σ_F
  const std::complex<double> psi = stiffness_term(law, at.bar);           // Ψ (eq. 30)
  const std::complex<double> phi = adhesion_term(law, at.bar);            // Φ (eq. 30)
  const std::complex<double> m = c.inverse_transfer + psi;                // M = L(iω)⁻¹ + Ψ
  const double m2 = std::norm(m);
  if (!(m2 > 0.0) || !std::isfinite(m2)) return out;
  const double m_abs = std::sqrt(m2);
  const std::complex<double> p = m * std::conj(phi);  // MΦ*
  const double gamma = c.drive;
  // E2 discriminant Γ²|M|² − Im(MΦ*)², factored to avoid cancellation.
  const double im_abs = std::abs(p.imag());
  const double disc = (gamma * m_abs - im_abs) * (gamma * m_abs + im_abs);
  if (disc < 0.0) return out;
  const double root = std::sqrt(disc);
  const double phi_abs = std::sqrt(std::norm(phi));
  const double product = (phi_abs - gamma) * (phi_abs + gamma) / m2;  // B₊B₋ = (|Φ|² − Γ²)/|M|²
  // Numerically stable roots: the one without cancellation directly, the other from the product.
  double b_plus;
  double b_minus;
  if (p.real() <= 0.0) {
    b_plus = (-p.real() + root) / m2;
    b_minus = b_plus != 0.0 ? product / b_plus : (-p.real() - root) / m2;
  } else {
    b_minus = (-p.real() - root) / m2;
    b_plus = b_minus != 0.0 ? product / b_minus : (-p.real() + root) / m2;
  }
  std::complex<double> dm;
  std::complex<double> dphi;
  if (with_slope) {
    dm = stiffness_term(law, at.dbar);
    dphi = adhesion_term(law, at.dbar);
  }
  for (const int sign : {+1, -1}) {
    HbBranchEvaluation& r = sign > 0 ? out.plus : out.minus;
    const double b = sign > 0 ? b_plus : b_minus;
    if (!(b > 0.0) || !std::isfinite(b)) continue;
    r.exists = true;
    r.amplitude = b;
    r.offset = c.static_gain * (sum_k * at.bar.omega * b - sum_f * at.bar.chi);  // E3
    r.separation = (at.gap < 0.5 ? b - at.gap * b : at.q * b) - r.offset;         // E4: l = qB − A
    const std::complex<double> z = m * b + phi;                                   // Γ e^{iφ} (E5)
    r.phase = std::atan2(z.imag(), z.real());
    if (!with_slope) continue;
    // Slope along the branch: F(B, θ) = |MB + Φ|² − Γ² = 0  ->  dB/dθ = −Re((M'B + Φ') z*) / Re(M z*).
    const double f_b = (m * std::conj(z)).real();
    const double f_theta = ((dm * b + dphi) * std::conj(z)).real();
    const double db = -f_theta / f_b;
    const double da = c.static_gain * (sum_k * (at.dbar.omega * b + at.bar.omega * db) - sum_f * at.dbar.chi);
    r.parameter_derivative = at.dq * b + at.q * db - da;
    r.separation_slope = r.parameter_derivative / at.dq;
  }
  return out;
}

Location permanent_location(double q) {
  if (!(q <= -1.0 && std::isfinite(q))) validate::require(false, "q", q, "finite and <= -1 (permanent contact)");
  return {q, 1.0 - q, pi, 1.0, bar_functions(q), bar_function_derivatives_permanent_contact()};
}

Location gap_location(double gap) {
  if (!(gap > 0.0 && std::isfinite(gap))) validate::require(false, "gap", gap, "finite and > 0 (q < 1: contact)");
  if (gap >= 2.0) return permanent_location(1.0 - gap);
  return contact_location(contact_bar_functions_from_gap(gap), gap);
}

const HbBranchEvaluation& pick(const HbRoots& roots, int sign) { return sign > 0 ? roots.plus : roots.minus; }

}  // namespace

// L(iω)⁻¹ = ω_n² − ω² + 2iξω_nω (eq. 9), written out rather than inverted numerically.
static std::complex<double> inverse_transfer_at_drive(const TappingModel& model) {
  const double wn = model.cantilever.natural_frequency;
  const double w = model.drive.frequency;
  return {wn * wn - w * w, 2.0 * model.cantilever.damping_ratio() * wn * w};
}

HbCoefficients::HbCoefficients(const TappingModel& model)
    : inverse_transfer(inverse_transfer_at_drive(model)),
      static_gain(model.cantilever.static_gain()),
      drive(model.drive.amplitude),
      law(require_piecewise_linear(model.law)) {}

HbBranchEvaluation evaluate_branch_at_angle(const HbCoefficients& c, double contact_angle, int sign) {
  const ContactBarFunctions b = contact_bar_functions_from_angle(contact_angle);
  const double half_sine = std::sin(0.5 * contact_angle);
  return pick(evaluate(c, contact_location(b, 2.0 * half_sine * half_sine), true), sign);
}

HbBranchEvaluation evaluate_branch_permanent(const HbCoefficients& c, double q, int sign) {
  return pick(evaluate(c, permanent_location(q), true), sign);
}

HbBranchEvaluation evaluate_branch_at_gap(const HbCoefficients& c, double gap, int sign) {
  return pick(evaluate(c, gap_location(gap), true), sign);
}

HbRoots evaluate_branches_at_gap(const HbCoefficients& c, double gap, bool with_slope) {
  return evaluate(c, gap_location(gap), with_slope);
}

}  // namespace afmkit::tapping
