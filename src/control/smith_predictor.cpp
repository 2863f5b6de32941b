#include "afmkit/control/smith_predictor.hpp"

#include <cmath>
#include <numbers>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

SmithPredictor::SmithPredictor(Bank b, PlantKind kind, double rate, double tau_hat, Structure s)
    : bank(std::move(b)),
      model_kind(kind),
      model_rate(validate::positive("model_rate", rate)),
      model_delay(validate::non_negative("model_delay", tau_hat)),
      structure(s) {}

double SmithPredictor::rotation_frequency() const {
  return std::visit(
      [](const auto& b) {
        if constexpr (std::is_same_v<std::decay_t<decltype(b)>, OscillatorBank>) return b.rotation_frequency();
        else return b.rotation_frequency;
      },
      bank);
}

double SmithPredictor::gain() const {
  return std::visit(
      [](const auto& b) {
        if constexpr (std::is_same_v<std::decay_t<decltype(b)>, OscillatorBank>) return b.gain();
        else return b.gain;
      },
      bank);
}

double SmithPredictor::period() const { return 2.0 * std::numbers::pi / rotation_frequency(); }

int SmithPredictor::model_periods() const {
  if (structure == Structure::Classic || model_delay == 0.0) return 0;
  return static_cast<int>(std::ceil(model_delay / period()));
}

double SmithPredictor::measurement_delay() const {
  if (structure == Structure::Classic) return 0.0;
  return std::max(0.0, model_periods() * period() - model_delay);
}

double SmithPredictor::correction_delay() const {
  if (structure == Structure::Classic) return model_delay;
  return model_periods() * period();
}

std::complex<double> SmithPredictor::model(std::complex<double> s) const {
  if (model_kind == PlantKind::Static) return 1.0 / model_rate;
  return 1.0 / (s + model_rate);
}

SmithRealisation smith_realisation(const SmithPredictor& sp) {
  const auto* bank = std::get_if<OscillatorBank>(&sp.bank);
  if (!bank)
    throw InvalidParameter("bank", "bank: a state-space realisation needs a finite OscillatorBank (the N = infinity "
                                   "bank is a neutral delay system, docs/theory-control.md#neutral-realisation)");
  return {ss(*bank), ss(sp.model_kind, sp.model_rate), sp.measurement_delay(), sp.correction_delay()};
}

}  // namespace afmkit::control
