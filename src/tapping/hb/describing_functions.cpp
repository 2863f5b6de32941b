#include "afmkit/tapping/describing_functions.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::tapping {

namespace {

constexpr double pi = std::numbers::pi;
constexpr double series_threshold = 0.5;  // contact angle below which the cancelling differences use series

// sin a − a cos a = Σ_{k≥1} (−1)^{k+1} 2k a^{2k+1}/(2k+1)!   (2π Ω̄ for small a)
double sin_minus_a_cos(double a) {
  const double a2 = a * a;
  double power = a * a2;  // a^{2k+1}
  double factorial = 6.0;  // (2k+1)!
  double sum = 0.0;
  double sign = 1.0;
  for (int k = 1; k <= 12; ++k) {
    sum += sign * 2.0 * k * power / factorial;
    power *= a2;
    factorial *= (2.0 * k + 2.0) * (2.0 * k + 3.0);
    sign = -sign;
  }
  return sum;
}

// a − sin a cos a = Σ_{k≥1} (−1)^{k+1} 4^k a^{2k+1}/(2k+1)!   (2π Ψ̄_R for small a)
double a_minus_sin_cos(double a) {
  const double a2 = a * a;
  double power = a * a2;
  double four_k = 4.0;
  double factorial = 6.0;
  double sum = 0.0;
  double sign = 1.0;
  for (int k = 1; k <= 12; ++k) {
    sum += sign * four_k * power / factorial;
    power *= a2;
    four_k *= 4.0;
    factorial *= (2.0 * k + 2.0) * (2.0 * k + 3.0);
    sign = -sign;
  }
  return sum;
}

BarFunctions no_contact() { return {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}; }

// q ≤ −1 (gap s ≥ 2): permanent contact, table A.6 last column.
BarFunctions permanent_contact(double q) { return {0.5, -0.5 * q, 0.0, 2.0 / pi, 0.5, -2.0 * q / pi}; }

// |q| < 1 from a = arccos q, sin a, cos a = q and the gap s = 1 − q (all consistent to rounding).
BarFunctions contact(double a, double sin_a, double cos_a, double gap) {
  const double sin_minus = a < series_threshold ? sin_minus_a_cos(a) : sin_a - a * cos_a;
  const double a_minus = a < series_threshold ? a_minus_sin_cos(a) : a - sin_a * cos_a;
  return {a / (2.0 * pi), sin_minus / (2.0 * pi), sin_a / pi, gap / pi, a_minus / (2.0 * pi),
          gap * gap / (2.0 * pi)};
}

}  // namespace

BarFunctions bar_functions_from_gap(double gap) {
  if (!std::isfinite(gap)) validate::finite("gap", gap);  // (checks only build strings on failure: hot path)
  if (gap <= 0.0) return no_contact();
  if (gap >= 2.0) return permanent_contact(1.0 - gap);
  // a = arccos(1 − s) = 2 asin(√(s/2)): accurate for s → 0; for s ≥ 1/2, 1 − s is exact (Sterbenz).
  const double a = gap < 0.5 ? 2.0 * std::asin(std::sqrt(0.5 * gap)) : std::acos(1.0 - gap);
  return contact(a, std::sqrt(gap * (2.0 - gap)), 1.0 - gap, gap);
}

BarFunctions bar_functions(double q) {
  if (!std::isfinite(q)) validate::finite("q", q);
  if (q >= 1.0) return no_contact();
  if (q <= -1.0) return permanent_contact(q);
  return bar_functions_from_gap(1.0 - q);
}

BarFunctions bar_functions_from_contact_angle(double angle) {
  if (!(angle >= 0.0 && angle <= pi)) validate::in_range("contact_angle", angle, 0.0, pi);
  if (angle == 0.0) return no_contact();
  const double half_sine = std::sin(0.5 * angle);
  return contact(angle, std::sin(angle), std::cos(angle), 2.0 * half_sine * half_sine);
}

BarFunctions bar_function_derivatives_in_angle(double angle) {
  if (!(angle >= 0.0 && angle <= pi)) validate::in_range("contact_angle", angle, 0.0, pi);
  const double s = std::sin(angle);
  const double c = std::cos(angle);
  const double half_sine = std::sin(0.5 * angle);
  const double gap = 2.0 * half_sine * half_sine;  // 1 − cos a
  return {1.0 / (2.0 * pi), angle * s / (2.0 * pi), c / pi, s / pi, s * s / pi, gap * s / pi};
}

BarFunctions bar_function_derivatives_permanent_contact() { return {0.0, -0.5, 0.0, 0.0, 0.0, -2.0 / pi}; }

std::complex<double> adhesion_term(const impact::PiecewiseLinearLaw& law, const BarFunctions& bar) {
  const double sum_f = law.approach_adhesion + law.departure_adhesion;    // Σ_F
  const double diff_f = law.departure_adhesion - law.approach_adhesion;   // Δ_F
  return {-sum_f * bar.phi_r, diff_f * bar.phi_i};
}

std::complex<double> stiffness_term(const impact::PiecewiseLinearLaw& law, const BarFunctions& bar) {
  const double sum_k = law.approach_stiffness + law.departure_stiffness;   // Σ_K
  const double diff_k = law.departure_stiffness - law.approach_stiffness;  // Δ_K
  return {sum_k * bar.psi_r, -diff_k * bar.psi_i};
}

DescribingFunctions describing_functions(const impact::PiecewiseLinearLaw& law, double q, double amplitude) {
  if (!(amplitude > 0.0 && std::isfinite(amplitude))) validate::positive("amplitude", amplitude);
  const BarFunctions bar = bar_functions(q);
  const double sum_f = law.approach_adhesion + law.departure_adhesion;
  const double sum_k = law.approach_stiffness + law.departure_stiffness;
  return {sum_f * bar.chi - sum_k * bar.omega * amplitude,
          adhesion_term(law, bar) / amplitude + stiffness_term(law, bar)};
}

const impact::PiecewiseLinearLaw& require_piecewise_linear(const impact::ForceLaw& law) {
  const impact::PiecewiseLinearLaw* linear = law.piecewise_linear();
  if (linear == nullptr)
    throw InvalidParameter("law", fmt::format("law = {} is not piecewise linear: describing functions and harmonic "
                                              "balance need the law of seed-1 eqs. (10), (11) or (26)",
                                              law.name()));
  return *linear;
}

DescribingFunctions describing_functions(const impact::ForceLaw& law, double q, double amplitude) {
  return describing_functions(require_piecewise_linear(law), q, amplitude);
}

DescribingFunctions describing_functions(const impact::ForceLaw& law, double offset, double amplitude,
                                         double separation) {
  validate::finite("offset", offset);
  validate::positive("amplitude", amplitude);
  validate::finite("separation", separation);
  return describing_functions(law, (offset + separation) / amplitude, amplitude);
}

}  // namespace afmkit::tapping
