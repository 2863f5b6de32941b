#include "afmkit/control/loop_family.hpp"

#include <fmt/format.h>

#include "afmkit/core/validate.hpp"

namespace afmkit::control {

LoopFamily LoopFamily::from_loop(const LoopSpec& loop) {
  LoopFamily f;
  f.rotation_frequency = loop.rotation_frequency();
  f.gain = loop.gain();
  f.plant_kind = loop.plant_kind;
  f.plant_rate = loop.plant_rate;
  f.delay = loop.delay;
  const auto set_bank = [&f](const Bank& b) {
    if (const auto* o = std::get_if<OscillatorBank>(&b)) {
      if (o->harmonics() == 1 && o->a0() == 0.0 && o->rejected() == std::vector<int>{1}) {
        f.kind = Kind::SingleOscillator;
      } else {
        f.kind = Kind::Bank;
        f.harmonics = o->harmonics();
        f.rejected = o->rejected();
      }
    } else {
      f.kind = Kind::Infinite;
    }
  };
  if (const auto* sp = std::get_if<SmithPredictor>(&loop.controller)) {
    set_bank(sp->bank);
    f.smith = SmithModel{sp->model_kind, sp->model_rate, sp->model_delay, sp->structure};
  } else if (const auto* o = std::get_if<OscillatorBank>(&loop.controller)) {
    set_bank(Bank(*o));
  } else {
    set_bank(Bank(std::get<InfiniteBank>(loop.controller)));
  }
  return f;
}

LoopSpec LoopFamily::at(double x, double y) const { return at(x, y, delay, gain / plant_rate); }

LoopSpec LoopFamily::at(double x, double y, double tau, double gain_ratio) const {
  validate::finite(x_name(), x);
  validate::finite(y_name(), y);
  validate::positive("gain_ratio", gain_ratio);
  Bank bank = [&]() -> Bank {
    switch (kind) {
      case Kind::SingleOscillator:
        return OscillatorBank::single(rotation_frequency, x, y, gain);
      case Kind::Bank:
        return OscillatorBank::with_couplings(rotation_frequency, harmonics, x, y, gain, rejected);
      case Kind::Infinite:
        break;
    }
    return InfiniteBank(rotation_frequency, x, y, gain);
  }();
  const double rate = gain / gain_ratio;
  if (smith) {
    return LoopSpec(SmithPredictor(std::move(bank), smith->model_kind, smith->model_rate, smith->model_delay,
                                   smith->structure),
                    plant_kind, rate, tau);
  }
  Controller c = std::visit([](auto&& b) -> Controller { return b; }, std::move(bank));
  return LoopSpec(std::move(c), plant_kind, rate, tau);
}

std::string LoopFamily::describe() const {
  std::string k = kind == Kind::SingleOscillator ? "single oscillator (a, b)"
                  : kind == Kind::Infinite       ? "N = infinity bank (alpha, beta)"
                                                 : fmt::format("bank N={} (alpha, beta)", harmonics);
  return fmt::format("{}{}, K={:g}, {} plant gamma={:g}, tau={:g}", k, smith ? " in a Smith predictor" : "", gain,
                     plant_kind == PlantKind::Static ? "static" : "first-order", plant_rate, delay);
}

}  // namespace afmkit::control
