#pragma once
// The cantilever of the fit tests: k = 40 N/m, f0 = 300 kHz, Q = 400, A0 = 20 nm at resonance (SI units).
#include "afmkit/spectroscopy/fit.hpp"

namespace afmkit_test {

inline afmkit::spectroscopy::FitSettings fit_settings() {
  afmkit::spectroscopy::FitSettings s;
  s.spring_constant = 40.0;
  s.resonance_frequency = 300e3;
  s.quality_factor = 400.0;
  s.free_amplitude = 20e-9;
  return s;
}

}  // namespace afmkit_test
