#pragma once
// Frequency response (python-control's `frequency_response`): G(iω) on a grid of angular frequencies,
// magnitude |G| and phase arg G unwrapped along the grid (radians; np.unwrap rule: jumps > π are folded).
// Exactly at a pole on the grid the magnitude is +inf and the phase NaN (the unwrapping skips it).
#include <complex>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include "afmkit/control/loop.hpp"
#include "afmkit/control/state_space.hpp"
#include "afmkit/control/transfer_function.hpp"

namespace afmkit::control {

struct FrequencyResponse {
  std::vector<double> omega;                       // ω [rad/s]
  std::vector<std::complex<double>> response;      // G(iω)
  std::vector<double> magnitude;                   // |G(iω)|
  std::vector<double> phase;                       // unwrapped arg G(iω) [rad]
  std::size_t size() const { return omega.size(); }
};

/// Grid of `points` angular frequencies in [omega_min, omega_max] (log spacing needs omega_min > 0).
/// Validated: 0 ≤ omega_min < omega_max finite, points ≥ 2.
std::vector<double> frequency_grid(double omega_min, double omega_max, int points, bool log_spacing);

/// Point i (0 ≤ i < points) of frequency_grid(omega_min, omega_max, points, log_spacing), computed alone (for
/// streaming a grid of any length in O(1) memory). Same values as the vector form.
double frequency_grid_point(double omega_min, double omega_max, long points, bool log_spacing, long i);

/// Streaming form of unwrap_phase: feed the raw phases in grid order, get the unwrapped ones (NaN passed through).
class PhaseUnwrapper {
 public:
  double operator()(double raw_phase);

 private:
  double offset_ = 0.0;
  double last_ = std::numeric_limits<double>::quiet_NaN();
};

/// The frequency-response row of a value G(iω): magnitude (+inf at a pole) and raw phase (NaN at a pole).
void magnitude_phase(std::complex<double> value, double& magnitude, double& raw_phase);

/// np.unwrap: adds multiples of 2π so that consecutive finite entries differ by at most π; NaN kept.
std::vector<double> unwrap_phase(std::vector<double> phase);

using FrequencyFunction = std::function<std::complex<double>(std::complex<double>)>;
FrequencyResponse frequency_response(const FrequencyFunction& system, std::span<const double> omegas);
FrequencyResponse frequency_response(const StateSpace& system, std::span<const double> omegas);
FrequencyResponse frequency_response(const TransferFunction& system, std::span<const double> omegas);
FrequencyResponse frequency_response(const Controller& controller, std::span<const double> omegas);

/// The frequency functions of a loop (loop.hpp).
enum class LoopSystem {
  Controller,   // C(s)
  Plant,        // P(s) = e^{−sτ} P0(s)
  Loop,         // L = P C
  Sensitivity,  // S = 1/(1 + L)
  ClosedLoop,   // disturbance f → output y
};
std::complex<double> evaluate(const LoopSpec& loop, LoopSystem which, std::complex<double> s);
FrequencyResponse frequency_response(const LoopSpec& loop, LoopSystem which, std::span<const double> omegas);

}  // namespace afmkit::control
