#include "afmkit/tapping/describing_functions.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/numerical_describing_functions.hpp"

namespace afmkit::tapping {

namespace {

using std::numbers::pi;  // (a using-declaration: repeatable in a unity build)
constexpr double series_threshold = 0.5;  // contact angle below which the cancelling differences use series

// Series of the two cancelling differences, in x = a²:
//   sin a − a cos a  = a³ Σ_{k≥1} (−1)^{k+1} 2k  x^{k−1}/(2k+1)!   (2π Ω̄)
//   a − sin a cos a  = a³ Σ_{k≥1} (−1)^{k+1} 4^k x^{k−1}/(2k+1)!   (2π Ψ̄_R)
// Ten terms reach rounding level for a < 0.5 (the 11th is below 1e-22 relative).
constexpr int series_terms = 10;
struct SeriesCoefficients {
  double omega[series_terms];
  double psi[series_terms];
};
constexpr SeriesCoefficients make_series() {
  SeriesCoefficients c{};
  double factorial = 6.0;  // (2k+1)!
  double four_k = 4.0;
  double sign = 1.0;
  for (int k = 1; k <= series_terms; ++k) {
    c.omega[k - 1] = sign * 2.0 * k / factorial;
    c.psi[k - 1] = sign * four_k / factorial;
    factorial *= (2.0 * k + 2.0) * (2.0 * k + 3.0);
    four_k *= 4.0;
    sign = -sign;
  }
  return c;
}
constexpr SeriesCoefficients series = make_series();

double horner(const double (&c)[series_terms], double x) {
  double sum = c[series_terms - 1];
  for (int k = series_terms - 2; k >= 0; --k) sum = sum * x + c[k];
  return sum;
}

BarFunctions no_contact() { return {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}; }

// q ≤ −1 (gap s ≥ 2): permanent contact, table A.6 last column.
BarFunctions permanent_contact(double q) { return {0.5, -0.5 * q, 0.0, 2.0 / pi, 0.5, -2.0 * q / pi}; }

// |q| < 1 from a = arccos q, sin a, cos a = q and the gap s = 1 − q (all consistent to rounding).
BarFunctions contact(double a, double sin_a, double cos_a, double gap) {
  const double a3 = a * a * a;
  const double sin_minus = a < series_threshold ? a3 * horner(series.omega, a * a) : sin_a - a * cos_a;
  const double a_minus = a < series_threshold ? a3 * horner(series.psi, a * a) : a - sin_a * cos_a;
  return {a / (2.0 * pi), sin_minus / (2.0 * pi), sin_a / pi, gap / pi, a_minus / (2.0 * pi),
          gap * gap / (2.0 * pi)};
}

// d/da of the bar functions (sin a, cos a, gap = 1 − cos a).
BarFunctions contact_derivatives(double a, double sin_a, double cos_a, double gap) {
  return {1.0 / (2.0 * pi), a * sin_a / (2.0 * pi), cos_a / pi, sin_a / pi, sin_a * sin_a / pi, gap * sin_a / pi};
}

}  // namespace

ContactBarFunctions contact_bar_functions_from_gap(double gap) {
  if (!(gap > 0.0 && gap < 2.0)) validate::require(false, "gap", gap, "in (0, 2) (|q| < 1: contact)");
  const double a = gap < 0.5 ? 2.0 * std::asin(std::sqrt(0.5 * gap)) : std::acos(1.0 - gap);
  const double sin_a = std::sqrt(gap * (2.0 - gap));
  const double cos_a = 1.0 - gap;
  return {a, sin_a, contact(a, sin_a, cos_a, gap), contact_derivatives(a, sin_a, cos_a, gap)};
}

ContactBarFunctions contact_bar_functions_from_angle(double angle) {
  if (!(angle >= 0.0 && angle <= pi)) validate::in_range("contact_angle", angle, 0.0, pi);
  const double half_sine = std::sin(0.5 * angle);
  const double gap = 2.0 * half_sine * half_sine;
  const double sin_a = std::sin(angle);
  const double cos_a = std::cos(angle);
  const BarFunctions value = angle == 0.0 ? no_contact() : contact(angle, sin_a, cos_a, gap);
  return {angle, sin_a, value, contact_derivatives(angle, sin_a, cos_a, gap)};
}

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
  return contact_bar_functions_from_angle(angle).angle_derivative;
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
  if (const impact::PiecewiseLinearLaw* linear = law.piecewise_linear())
    return describing_functions(*linear, q, amplitude);  // closed form (fast path)
  if (!std::isfinite(q)) validate::finite("q", q);
  if (!(amplitude > 0.0 && std::isfinite(amplitude))) validate::positive("amplitude", amplitude);
  if (law.has_damping())
    throw InvalidParameter("frequency", fmt::format("law = {} has a velocity (Kelvin–Voigt) term: its describing "
                                                    "functions depend on the drive frequency; use the overload "
                                                    "with the frequency",
                                                    law.name()));
  return DescribingFunctionQuadrature(law, 1.0).at_gap(q * amplitude, amplitude);  // (ω irrelevant)
}

DescribingFunctions describing_functions(const impact::ForceLaw& law, double offset, double amplitude,
                                         double separation) {
  validate::finite("offset", offset);
  validate::positive("amplitude", amplitude);
  validate::finite("separation", separation);
  return describing_functions(law, (offset + separation) / amplitude, amplitude);
}

DescribingFunctions describing_functions(const impact::ForceLaw& law, double offset, double amplitude,
                                         double separation, double frequency) {
  validate::finite("offset", offset);
  validate::positive("amplitude", amplitude);
  validate::finite("separation", separation);
  validate::positive("frequency", frequency);
  if (const impact::PiecewiseLinearLaw* linear = law.piecewise_linear())
    return describing_functions(*linear, (offset + separation) / amplitude, amplitude);
  return DescribingFunctionQuadrature(law, frequency).at_gap(offset + separation, amplitude);
}

}  // namespace afmkit::tapping
