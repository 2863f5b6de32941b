#include "afmkit/tapping/parameter.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "sweep_points.hpp"

namespace afmkit::tapping {

SweepParameter::SweepParameter(std::string name, ModelAt model_at) : name_(std::move(name)), model_at_(std::move(model_at)) {
  if (name_.empty()) throw InvalidParameter("parameter", "the swept parameter needs a name");
  if (!model_at_) throw InvalidParameter("parameter", "parameter " + name_ + " has no model function");
}

SweepParameter SweepParameter::separation() {
  SweepParameter p("separation", [](const TappingModel& base, double l) { return base.with_separation(l); });
  p.separation_ = true;
  return p;
}

SweepParameter SweepParameter::drive_frequency() {
  return {"drive_frequency", [](const TappingModel& base, double omega) {
            return TappingModel(base.cantilever, Drive(base.drive.amplitude, omega), base.law, base.separation);
          }};
}

SweepParameter SweepParameter::drive_amplitude() {
  return {"drive_amplitude", [](const TappingModel& base, double gamma) {
            return TappingModel(base.cantilever, Drive(gamma, base.drive.frequency), base.law, base.separation);
          }};
}

TappingModel SweepParameter::at(const TappingModel& base, double value) const { return model_at_(base, value); }

namespace detail {

ParameterPath make_path(const TappingModel& base, const SweepParameter& parameter, double p_min, double p_max) {
  ParameterPath path{base, parameter};
  path.width = std::abs(p_max - p_min);
  if (!parameter.is_separation()) {
    const double magnitude = std::max(std::abs(p_min), std::abs(p_max));
    const double amplitude = base.free_amplitude();
    path.scale = magnitude > 0 && amplitude > 0 && std::isfinite(amplitude / magnitude) ? amplitude / magnitude : 1.0;
  }
  return path;
}

double ParameterPath::difference_step(double value) const { return 1e-5 * std::max(std::abs(value), width); }

namespace {

/// ∂P^n/∂p at `start` by central differences of the map (P^n(start) = `end` at p = value), one-sided where the
/// model refuses p ± h (a parameter at the edge of its range, e.g. an adhesion of 0).
Eigen::Vector2d difference_of_map(const ParameterPath& path, double value, TipState start, TipState end, int n,
                                  const SimulationOptions& simulation) {
  SimulationOptions plain = simulation;
  plain.sensitivity = false;
  const double h = path.difference_step(value);
  const auto end_at = [&](double p) -> std::optional<TipState> {
    std::optional<TappingModel> model;
    try {
      model.emplace(path.at(p));
    } catch (const InvalidParameter&) {
      return std::nullopt;
    }
    return stroboscopic_map(*model, start, n, plain).end;
  };
  const std::optional<TipState> up = end_at(value + h), down = end_at(value - h);
  const auto diff = [](const TipState& a, const TipState& b, double d) {
    return Eigen::Vector2d((a.position - b.position) / d, (a.velocity - b.velocity) / d);
  };
  if (up && down) return diff(*up, *down, 2 * h);
  if (up) return diff(*up, end, h);
  if (down) return diff(end, *down, h);
  throw NumericalFailure(fmt::format("continuation in {}: no model at {} ± {} to take the derivative of the "
                                     "stroboscopic map",
                                     path.parameter.name(), value, h));
}

}  // namespace

Eigen::Vector2d ParameterPath::map_derivative(double value, TipState start, TipState end,
                                              const SimulationOptions& simulation) const {
  return difference_of_map(*this, value, start, end, 1, simulation);
}

Eigen::Vector2d ParameterPath::orbit_derivative(const PeriodicOrbit& orbit, double value,
                                                const SimulationOptions& simulation) const {
  if (parameter.is_separation()) return orbit.separation_sensitivity;
  return difference_of_map(*this, value, orbit.initial, orbit.initial, orbit.period_multiple, simulation);
}

}  // namespace detail

}  // namespace afmkit::tapping
