// Large-stiffness approximations (seed-1 eqs. 20–25) and the q → −∞ limit (seed-1 ext. E8,
// docs/theory-tapping.md#minimum-separation).
#include "afmkit/tapping/hb_approximations.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/describing_functions.hpp"
#include "afmkit/tapping/hb_branch.hpp"

namespace afmkit::tapping {

namespace {

using std::numbers::pi;  // (a using-declaration: repeatable in a unity build)

const impact::PiecewiseLinearLaw& require_repulsive(const TappingModel& model, const char* equation) {
  const impact::PiecewiseLinearLaw& law = require_piecewise_linear(model.law);
  if (law.approach_adhesion != 0.0 || law.departure_adhesion != 0.0)
    throw InvalidParameter("law", fmt::format("{} holds for the repulsive laws (10), (11) only: F_a = {}, F_b = {} "
                                              "must be 0",
                                              equation, law.approach_adhesion, law.departure_adhesion));
  return law;
}

// M(q) = L(iω)⁻¹ + N1(q) of eq. (18) for a repulsive law (N1 = Ψ(q)).
std::complex<double> repulsive_m(const TappingModel& model, double q) {
  const HbCoefficients c(model);
  return c.inverse_transfer + stiffness_term(c.law, bar_functions(q));
}

// Γ|L(iω_n)| = Γ/(2ξω_n²): the resonant free amplitude, the scale of eq. (25).
double resonant_free_amplitude(const TappingModel& model) {
  const double wn = model.cantilever.natural_frequency;
  return model.drive.amplitude / (2.0 * model.cantilever.damping_ratio() * wn * wn);
}

}  // namespace

double impulsive_separation(double amplitude, double offset) {
  validate::positive("amplitude", amplitude);
  validate::finite("offset", offset);
  return amplitude - offset;
}

double impulsive_offset_bound(const TappingModel& model) {
  return model.drive.amplitude * model.cantilever.static_gain();
}

double impulsive_amplitude(const TappingModel& model) {
  validate::require(model.separation >= 0.0, "separation", model.separation, ">= 0");
  return std::min(model.separation, model.free_amplitude());
}

double repulsive_phase_sine(const TappingModel& model, double q) {
  require_repulsive(model, "eq. (23)");
  const std::complex<double> m = repulsive_m(model, q);
  return m.imag() / std::abs(m);
}

double repulsive_separation_from_phase(const TappingModel& model, double q) {
  const impact::PiecewiseLinearLaw& law = require_repulsive(model, "eq. (24)");
  validate::finite("q", q);
  validate::require(q > -1.0 && q < 1.0, "q", q, "in (-1, 1) (contact)");
  const double sum_k = law.approach_stiffness + law.departure_stiffness;
  const double sin_phase = repulsive_phase_sine(model, q);
  const double im_m = repulsive_m(model, q).imag();
  const double bracket =
      q + model.cantilever.static_gain() * sum_k / (2.0 * pi) * (q * std::acos(q) - std::sqrt(1.0 - q * q));
  return bracket * model.drive.amplitude * sin_phase / im_m;
}

double impulsive_separation_from_phase(const TappingModel& model, double phase) {
  validate::finite("phase", phase);
  return resonant_free_amplitude(model) * std::sin(phase);
}

double impulsive_phase(const TappingModel& model) {
  const double scale = resonant_free_amplitude(model);
  validate::require(model.separation >= 0.0 && model.separation <= scale, "separation", model.separation,
                    fmt::format("in [0, Γ|L(iω_n)|] = [0, {}]", scale));
  return std::asin(model.separation / scale);
}

std::optional<double> minimum_separation_limit(const TappingModel& model) {
  const impact::PiecewiseLinearLaw& law = require_piecewise_linear(model.law);
  const double sum_k = law.approach_stiffness + law.departure_stiffness;
  const double sum_f = law.approach_adhesion + law.departure_adhesion;
  const double kappa = 2.0 * (law.approach_stiffness - law.departure_stiffness) / pi;
  const double delta = 2.0 * (law.departure_adhesion - law.approach_adhesion) / pi;
  const double gamma = model.drive.amplitude;
  const double l0 = model.cantilever.static_gain();
  if (kappa == 0.0) {  // M and Φ are constant for q ≤ −1: B₊ is constant and l = qB₊(1 + L(0)Σ_K/2) + … → −∞
    if (evaluate_branch_permanent(HbCoefficients(model), -2.0, +1).exists)
      return -std::numeric_limits<double>::infinity();
    return std::nullopt;
  }
  const double effective_drive = gamma - std::copysign(delta, kappa);
  if (!(effective_drive > 0.0)) return std::nullopt;
  return -(1.0 + l0 * sum_k / 2.0) * effective_drive / std::abs(kappa) + l0 * sum_f / 2.0;
}

}  // namespace afmkit::tapping
