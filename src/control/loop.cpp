#include "afmkit/control/loop.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/validate.hpp"
#include "controller_parts.hpp"

namespace afmkit::control {

using detail::cplx;
using detail::Dual;
using detail::Scaled;

namespace {
std::string describe_bank(const Bank& b) {
  if (const auto* o = std::get_if<OscillatorBank>(&b)) {
    std::string rej;
    for (int k : o->rejected()) rej += fmt::format("{}{}", rej.empty() ? "" : ",", k);
    return fmt::format("bank N={} a0={:g} a1={:g} b1={:g} K={:g} rejected={{{}}} Omega={:g}", o->harmonics(), o->a0(),
                       o->a(1), o->b(1), o->gain(), rej, o->rotation_frequency());
  }
  const auto& i = std::get<InfiniteBank>(b);
  return fmt::format("infinite bank alpha={:g} beta={:g} K={:g} Omega={:g}", i.alpha, i.beta, i.gain,
                     i.rotation_frequency);
}
// Bank parts of a plain (non-Smith) controller without copying the bank (O(N) per call, no allocation).
detail::BankParts plain_parts(const Controller& c, cplx s) {
  if (const auto* o = std::get_if<OscillatorBank>(&c)) return detail::bank_parts(*o, s);
  if (const auto* i = std::get_if<InfiniteBank>(&c)) return detail::bank_parts(*i, s);
  return detail::bank_parts(std::get<SmithPredictor>(c).bank, s);
}
const char* plant_name(PlantKind k) { return k == PlantKind::FirstOrder ? "first-order" : "static"; }

// M(s) = 1 (static) or 1 + s/γ (first order): P0 = 1/(γ M).
Dual plant_factor(PlantKind kind, double rate, cplx s) {
  if (kind == PlantKind::Static) return Dual(1.0, 0.0);
  return Dual(1.0 + s / rate, 1.0 / rate);
}
}  // namespace

LoopSpec::LoopSpec(Controller c, PlantKind kind, double rate, double tau)
    : controller(std::move(c)),
      plant_kind(kind),
      plant_rate(validate::positive("plant_rate", rate)),
      delay(validate::non_negative("delay", tau)) {}

double LoopSpec::rotation_frequency() const {
  return std::visit(
      [](const auto& c) {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, SmithPredictor>) return c.rotation_frequency();
        else if constexpr (std::is_same_v<T, OscillatorBank>) return c.rotation_frequency();
        else return c.rotation_frequency;
      },
      controller);
}
double LoopSpec::period() const { return 2.0 * std::numbers::pi / rotation_frequency(); }
double LoopSpec::gain() const {
  return std::visit(
      [](const auto& c) {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, SmithPredictor>) return c.gain();
        else if constexpr (std::is_same_v<T, OscillatorBank>) return c.gain();
        else return c.gain;
      },
      controller);
}
double LoopSpec::gain_ratio() const { return gain() / plant_rate; }
LoopSpec LoopSpec::with_delay(double tau) const { return LoopSpec(controller, plant_kind, plant_rate, tau); }

std::string LoopSpec::describe() const {
  std::string c = std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, SmithPredictor>) {
          return fmt::format("Smith predictor ({}, model {} gamma_hat={:g} tau_hat={:g}) around {}",
                             x.structure == SmithPredictor::Structure::Periodic ? "periodic" : "classic",
                             plant_name(x.model_kind), x.model_rate, x.model_delay, describe_bank(x.bank));
        } else {
          return describe_bank(Bank(x));
        }
      },
      controller);
  return fmt::format("{}; {} plant gamma={:g}, tau={:g}", c, plant_name(plant_kind), plant_rate, delay);
}

ScaledCharacteristic characteristic_scaled(const LoopSpec& loop, std::complex<double> s) {
  const Dual m = plant_factor(loop.plant_kind, loop.plant_rate, s);
  Scaled delta;
  if (const auto* sp = std::get_if<SmithPredictor>(&loop.controller)) {
    const detail::BankParts parts = detail::bank_parts(sp->bank, s);
    const Dual mh = plant_factor(sp->model_kind, sp->model_rate, s);
    const Scaled e_c = detail::delay_factor(s, sp->correction_delay());
    const Scaled e_m = detail::delay_factor(s, sp->measurement_delay() + loop.delay);
    // Δ = M M̂ d + Kn [M (1 − e^{−sτ_c})/γ̂ + M̂ e^{−s(τ_m+τ)}/γ]
    const Scaled corr{(1.0 / sp->model_rate) * m, 0.0};
    const Scaled bracket = corr + Scaled{Dual(-1.0), 0.0} * (corr * e_c) + Scaled{(1.0 / loop.plant_rate) * mh, 0.0} * e_m;
    delta = Scaled{m * mh * parts.d, parts.ls} + parts.scaled_kn() * bracket;
  } else {
    const detail::BankParts parts = plain_parts(loop.controller, s);
    // Δ = M d + Kn e^{−sτ}/γ
    delta = Scaled{m * parts.d, parts.ls} +
            Scaled{(1.0 / loop.plant_rate) * parts.kn, parts.ls} * detail::delay_factor(s, loop.delay);
  }
  return {delta.x.v, delta.x.d, delta.ls};
}

std::complex<double> characteristic(const LoopSpec& loop, std::complex<double> s) {
  const auto c = characteristic_scaled(loop, s);
  return detail::rescale(c.value, c.log_scale);
}

std::complex<double> characteristic_derivative(const LoopSpec& loop, std::complex<double> s) {
  const auto c = characteristic_scaled(loop, s);
  return detail::rescale(c.derivative, c.log_scale);
}

std::complex<double> newton_step(const LoopSpec& loop, std::complex<double> s) {
  const auto c = characteristic_scaled(loop, s);
  return c.value / c.derivative;
}

// ---------------------------------------------------------------- frequency functions
namespace {
struct SmithTerms {
  cplx d, kn, a_m, pi_corr;  // bank parts (common scale dropped), A_m, Π
};
SmithTerms smith_terms(const SmithPredictor& sp, cplx s) {
  const detail::BankParts parts = detail::bank_parts(sp.bank, s);
  SmithTerms t;
  t.d = parts.d.v;
  t.kn = parts.kn.v;
  t.a_m = std::exp(-s * sp.measurement_delay());
  t.pi_corr = sp.model(s) * (1.0 - std::exp(-s * sp.correction_delay()));
  return t;
}
cplx safe_ratio(cplx num, cplx den) {
  if (den == 0.0) {
    if (num == 0.0) return {std::numeric_limits<double>::quiet_NaN(), 0.0};
    return {std::numeric_limits<double>::infinity(), 0.0};
  }
  return num / den;
}
}  // namespace

std::complex<double> controller_response(const Controller& controller, std::complex<double> s) {
  if (const auto* sp = std::get_if<SmithPredictor>(&controller)) {
    const SmithTerms t = smith_terms(*sp, s);
    return safe_ratio(t.kn * t.a_m, t.d + t.kn * t.pi_corr);
  }
  const detail::BankParts parts = plain_parts(controller, s);
  return detail::ratio(parts.kn, parts.d);
}

std::complex<double> plant_response_delay_free(const LoopSpec& loop, std::complex<double> s) {
  if (loop.plant_kind == PlantKind::Static) return 1.0 / loop.plant_rate;
  return safe_ratio(1.0, s + loop.plant_rate);
}

std::complex<double> plant_response(const LoopSpec& loop, std::complex<double> s) {
  return std::exp(-s * loop.delay) * plant_response_delay_free(loop, s);
}

std::complex<double> loop_response(const LoopSpec& loop, std::complex<double> s) {
  const cplx c = controller_response(loop.controller, s);
  if (std::isinf(c.real()) || std::isinf(c.imag())) return {std::numeric_limits<double>::infinity(), 0.0};
  return plant_response(loop, s) * c;
}

std::complex<double> sensitivity(const LoopSpec& loop, std::complex<double> s) {
  const cplx p = plant_response(loop, s);
  if (const auto* sp = std::get_if<SmithPredictor>(&loop.controller)) {
    const SmithTerms t = smith_terms(*sp, s);
    const cplx open = t.d + t.kn * t.pi_corr;  // S = (d + KnΠ)/(d + KnΠ + Kn A_m P)
    return safe_ratio(open, open + t.kn * t.a_m * p);
  }
  const detail::BankParts parts = plain_parts(loop.controller, s);
  return safe_ratio(parts.d.v, parts.d.v + parts.kn.v * p);  // S = d/(d + Kn P)
}

std::complex<double> disturbance_response(const LoopSpec& loop, std::complex<double> s) {
  const cplx sens = sensitivity(loop, s);
  if (loop.plant_kind == PlantKind::Static) return sens;
  return safe_ratio(loop.plant_rate * sens, s + loop.plant_rate);
}

}  // namespace afmkit::control
