#pragma once
// The ranges of a cantilever's measured settings (spring constant, resonance frequency, quality factor, an
// oscillation amplitude), declared once for the library and the command line: the library's settings
// (spectroscopy::FitSettings, FmFitSettings, the spring constant of spectroscopy prepare, tapping::PhysicalCantilever)
// check a value given in SI or in a unit of the registry with check_cantilever_setting(), the command line declares its cantilever keys with cantilever_limit() in its own
// units (apps/cantilever_params.cpp: kHz, nm). A value is in (0, upper]: wide but finite, so that the model's scales
// stay far inside the double range (real cantilevers lie decades inside). The units are the unit registry's
// (afmkit/core/units.hpp), each an SI unit.
#include <string_view>

#include "afmkit/core/units.hpp"

namespace afmkit::tapping {

/// What a cantilever setting measures.
enum class CantileverSetting {
  spring_constant,      // k [N/m], in (0, 1e6]
  resonance_frequency,  // f0 [Hz], in (0, 1e10] (1e7 kHz)
  quality_factor,       // Q, dimensionless, in (0, 1e9]
  amplitude             // a free or held oscillation amplitude [m], in (0, 1e-3] (1e6 nm)
};

/// The SI unit of a setting (the registry's: N/m, Hz, dimensionless, m) and the largest value it may take in that
/// unit (the smallest: > 0).
struct CantileverLimit {
  units::SiUnit unit;
  double upper;  // in unit
};

constexpr CantileverLimit cantilever_limit(CantileverSetting s) {
  switch (s) {
    case CantileverSetting::spring_constant: return {units::si_unit("N/m"), 1e6};
    case CantileverSetting::resonance_frequency: return {units::si_unit("Hz"), 1e10};
    case CantileverSetting::quality_factor: return {units::si_unit("dimensionless"), 1e9};
    case CantileverSetting::amplitude: return {units::si_unit("m"), 1e-3};
  }
  return {units::si_unit("dimensionless"), 0.0};  // unreachable: every setting is listed above
}

/// `value` (SI) when it is in (0, upper] of `setting`; otherwise InvalidParameter naming `key`, the value and the
/// range with their unit ("free_amplitude = 1e+300 m is out of range: must be > 0 and <= 0.001 m").
double check_cantilever_setting(const char* key, CantileverSetting setting, double value);

/// `value` given in `unit` (a unit of the registry for the setting's quantity: "kHz", "nm", …) when it is in
/// (0, upper] of `setting`, its upper end converted into `unit` as the command line converts it (units::from_si, so
/// that both take the same values); otherwise InvalidParameter naming `key`, the value and the range in `unit`
/// ("free_amplitude = 2e+06 nm is out of range: must be > 0 and <= 1e+06 nm"). tapping::PhysicalCantilever's.
double check_cantilever_setting(const char* key, CantileverSetting setting, double value, std::string_view unit);

}  // namespace afmkit::tapping
