#include "afmkit/tapping/units.hpp"

#include <cmath>
#include <numbers>

#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/cantilever_limits.hpp"

namespace afmkit::tapping {

PhysicalCantilever::PhysicalCantilever(double k, double f0, double q, double a_free, double ratio)
    // the ranges of the command line and Python (tapping/cantilever_limits.hpp), in this type's units
    : spring_constant(check_cantilever_setting("spring_constant", CantileverSetting::spring_constant, k, "N/m")),
      resonance_frequency(
          check_cantilever_setting("resonance_frequency", CantileverSetting::resonance_frequency, f0, "kHz")),
      quality_factor(check_cantilever_setting("quality_factor", CantileverSetting::quality_factor, q, "dimensionless")),
      free_amplitude(check_cantilever_setting("free_amplitude", CantileverSetting::amplitude, a_free, "nm")),
      frequency_ratio(validate::positive("frequency_ratio", ratio)) {}

Drive PhysicalCantilever::drive() const {
  const Cantilever c = cantilever();
  const double gain = std::abs(c.transfer({0.0, frequency_ratio}));  // |L(iω)|, ω_n = 1
  return {free_amplitude / gain, frequency_ratio};
}

impact::ForceLaw PhysicalCantilever::normalised_law(const impact::ForceLaw& physical) const {
  return physical.scaled(1.0 / spring_constant, 2.0 * std::numbers::pi * resonance_frequency * 1e3);
}

UnitScales PhysicalCantilever::scales() const {
  UnitScales s;
  s.length = 1.0;
  s.force = spring_constant;
  s.energy = spring_constant;
  s.time = 1.0 / (2.0 * std::numbers::pi * resonance_frequency * 1e3);
  s.length_unit = "nm";
  s.force_unit = "nN";
  s.energy_unit = "aJ";
  s.time_unit = "s";
  return s;
}

}  // namespace afmkit::tapping
