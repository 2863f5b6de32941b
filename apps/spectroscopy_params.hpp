#pragma once
// Parameters that several spectroscopy commands share, declared once (tests/cli/test_declared_once.cpp).
#include "afmkit/core/units.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/tapping/cantilever_limits.hpp"

namespace afmkit::cli {

/// The AM drive frequency of spectroscopy fit and reconstruct: kHz, = resonance_frequency when not given (the
/// records give the value used); 0 also drives at the resonance frequency.
inline void add_drive_frequency_param(io::ParamSet& p) {
  // the resonance frequency's bound (tapping/cantilever_limits.hpp, in SI), in kHz; 0: at the resonance
  const double upper = units::from_si("kHz")(
      tapping::cantilever_limit(tapping::CantileverSetting::resonance_frequency).upper);
  p.real("drive_frequency", 0.0, "AM: drive frequency (0: at the resonance frequency)", io::Range::closed(0.0, upper))
      .unit("kHz")
      .follows("resonance_frequency");
}

}  // namespace afmkit::cli
