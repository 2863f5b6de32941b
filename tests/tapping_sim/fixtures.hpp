#pragma once
// Shared models of the tapping-simulation tests (docs/theory-tapping.md#hb-accuracy parameters: ω_n = 1, Q = 100, Γ =
// 0.2).
#include "afmkit/tapping/model.hpp"

namespace afmkit::tapping::testing {

inline TappingModel make_model(double ka, double kb, double fa, double fb, double separation, double omega = 1.0,
                               double quality = 100.0, double gamma = 0.2) {
  return TappingModel(Cantilever(1.0, quality), Drive(gamma, omega),
                      impact::ForceLaw(impact::PiecewiseLinearLaw(ka, kb, fa, fb)), separation);
}

/// Hysteresis law (11): K_a = 10, K_b = 8, l = 10.
inline TappingModel repulsive_model(double separation = 10.0) { return make_model(10, 8, 0, 0, separation); }
/// Repulsive–attractive law (26): K_a = 10, K_b = 8, F_a = 0.3, F_b = 0.6.
inline TappingModel attractive_model(double separation = 10.0) { return make_model(10, 8, 0.3, 0.6, separation); }

}  // namespace afmkit::tapping::testing
