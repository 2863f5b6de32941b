#pragma once
// Parameters that several spectroscopy commands share, declared once (tests/cli/test_declared_once.cpp).
#include "afmkit/io/params.hpp"

namespace afmkit::cli {

/// The AM drive frequency of spectroscopy fit and reconstruct: kHz, = resonance_frequency when not given (the
/// records give the value used); 0 also drives at the resonance frequency.
inline void add_drive_frequency_param(io::ParamSet& p) {
  p.real("drive_frequency", 0.0, "AM: drive frequency (0: at the resonance frequency)", io::Range::closed(0.0, 1e7))
      .unit("kHz")
      .follows("resonance_frequency");
}

}  // namespace afmkit::cli
