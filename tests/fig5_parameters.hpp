#pragma once
// The controller parameters of seed 003's figures 3 and 5 (docs/theory-control.md#simulation), shared by the control
// test programs: rotation frequency Ω = 1, its period T = 2π/Ω, and γ = 20 Ω. One declaration, so that the files of
// a test program (compiled as one unity file, docs/development.md#build-time) do not define them twice.
#include <numbers>

namespace afmkit_test::fig5 {
inline constexpr double kOmega = 1.0;                         // Ω
inline constexpr double kT = 2.0 * std::numbers::pi / kOmega;  // T = 2π/Ω
inline constexpr double kGamma = 20.0 * kOmega;               // γ = 20 Ω
}  // namespace afmkit_test::fig5
