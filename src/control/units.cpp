// Units of the control loop (units.hpp): Ω and T ↔ rad/s and s, and the loop described in Ω and T.
#include "afmkit/control/units.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <type_traits>
#include <variant>

#include <fmt/format.h>

#include "afmkit/core/validate.hpp"

namespace afmkit::control {

RotationUnits::RotationUnits(double rotation_frequency)
    : omega_(validate::positive("rotation_frequency", rotation_frequency)),
      period_(2.0 * std::numbers::pi / rotation_frequency) {}

namespace {
// a0 = α, a_k = 2α, b_k = −2β/k (eq. 20), to rounding
bool follows_couplings(const OscillatorBank& o) {
  const auto close = [](double x, double y) { return std::abs(x - y) <= 1e-12 * (std::abs(x) + std::abs(y)); };
  for (int k = 1; k <= o.harmonics(); ++k)
    if (!close(o.a(k), 2.0 * o.a0()) || !close(k * o.b(k), o.b(1))) return false;
  return true;
}
std::string bank_text(const Bank& bank, const RotationUnits& u) {
  if (const auto* o = std::get_if<OscillatorBank>(&bank)) {
    std::string rej;
    for (int k : o->rejected()) rej += fmt::format("{}{}", rej.empty() ? "" : ",", k);
    if (o->harmonics() == 1 && o->a0() == 0.0)
      return fmt::format("single oscillator a={:g} Omega b={:g} Omega K={:g} Omega", u.in_omega(o->a(1)),
                         u.in_omega(o->b(1)), u.in_omega(o->gain()));
    if (!follows_couplings(*o))
      return fmt::format("bank N={} a0={:g} Omega a1={:g} Omega b1={:g} Omega K={:g} Omega rejected={{{}}}",
                         o->harmonics(), u.in_omega(o->a0()), u.in_omega(o->a(1)), u.in_omega(o->b(1)),
                         u.in_omega(o->gain()), rej);
    // couplings (20): a0 = α, b_1 = −2β
    return fmt::format("bank N={} alpha={:g} Omega beta={:g} Omega K={:g} Omega rejected={{{}}}", o->harmonics(),
                       u.in_omega(o->a0()), u.in_omega(-0.5 * o->b(1)), u.in_omega(o->gain()), rej);
  }
  const auto& i = std::get<InfiniteBank>(bank);
  return fmt::format("infinite bank alpha={:g} Omega beta={:g} Omega K={:g} Omega", u.in_omega(i.alpha),
                     u.in_omega(i.beta), u.in_omega(i.gain));
}
const char* plant_text(PlantKind k) { return k == PlantKind::FirstOrder ? "first-order" : "static"; }
}  // namespace

std::string describe_in_rotation_units(const LoopSpec& loop) {
  const RotationUnits u(loop.rotation_frequency());
  const std::string c = std::visit(
      [&u](const auto& x) -> std::string {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, SmithPredictor>)
          return fmt::format("Smith predictor ({}, model {} gamma_hat={:g} Omega tau_hat={:g} T) around {}",
                             x.structure == SmithPredictor::Structure::Periodic ? "periodic" : "classic",
                             plant_text(x.model_kind), u.in_omega(x.model_rate), u.in_periods(x.model_delay),
                             bank_text(x.bank, u));
        else
          return bank_text(Bank(x), u);
      },
      loop.controller);
  return fmt::format("{}; {} plant gamma={:g} Omega, tau={:g} T (Omega = {:g} rad/s)", c, plant_text(loop.plant_kind),
                     u.in_omega(loop.plant_rate), u.in_periods(loop.delay), u.rotation_frequency());
}

}  // namespace afmkit::control
