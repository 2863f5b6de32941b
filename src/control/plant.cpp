#include "afmkit/control/plant.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

Disturbance::Disturbance(double c0, std::vector<Harmonic> h) : offset(validate::finite("offset", c0)), harmonics(std::move(h)) {
  for (std::size_t i = 0; i < harmonics.size(); ++i) {
    const auto& hk = harmonics[i];
    validate::in_range("harmonic order", static_cast<long>(hk.order), 1L, 1000000L);
    validate::non_negative(fmt::format("amplitude of harmonic {}", hk.order), hk.amplitude);
    validate::finite(fmt::format("phase of harmonic {}", hk.order), hk.phase);
    for (std::size_t j = 0; j < i; ++j)
      if (harmonics[j].order == hk.order)
        throw InvalidParameter("harmonic order", fmt::format("harmonic {} is given twice", hk.order));
  }
}

double Disturbance::operator()(double theta) const {
  double f = offset;
  for (const auto& h : harmonics) f += h.amplitude * std::sin(h.order * theta + h.phase);
  return f;
}

Disturbance Disturbance::paper_example(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  std::vector<Harmonic> h{{1, 1.0, 0.0}};
  for (int k = 2; k <= 8; ++k) h.push_back({k, 0.3 / k, phase(rng)});
  return Disturbance(0.2, std::move(h));
}

Plant::Plant(PlantKind k, double g, double omega, double tau, Disturbance f, double dv, double dvf)
    : kind(k),
      rate(validate::positive("plant_rate", g)),
      rotation_frequency(validate::positive("rotation_frequency", omega)),
      delay(validate::non_negative("delay", tau)),
      disturbance(std::move(f)),
      delay_variation(validate::non_negative("delay_variation", dv)),
      delay_variation_frequency(validate::non_negative("delay_variation_frequency", dvf)) {
  validate::require(dv <= tau, "delay_variation", dv, fmt::format("<= delay = {} (the delay must stay >= 0)", tau));
}

double Plant::period() const { return 2.0 * std::numbers::pi / rotation_frequency; }
bool Plant::delay_exceeds_period() const { return delay + delay_variation >= period(); }
double Plant::delay_at(double t) const {
  return delay + delay_variation * std::sin(delay_variation_frequency * t);
}

}  // namespace afmkit::control
