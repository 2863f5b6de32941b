// How much measurement delay does the first-harmonic rejection loop tolerate? (seed 2,
// docs/theory-control.md#delay-margin)
//
// A rotational-scanning AFM turns the sample at f_rot = 10 Hz; the height loop (static plant, rate γ = 20 Ω)
// removes the sample tilt (first harmonic) with the oscillator-bank controller (couplings α = 0.1 Ω,
// β = −0.1 Ω, gain K = γ) while keeping the topography harmonics 2..N. The height signal is measured with a delay
// τ: the loop stays stable for τ < τ_c (delay margin). This program prints τ_c in milliseconds and in rotation
// periods for several bank sizes N, then checks the margin of one design by counting the closed-loop roots in
// the right half plane just below and just above it (argument principle, an independent computation).
//
// Build against the installed library: examples/README.md.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <afmkit/control/delay_margin.hpp>
#include <afmkit/control/infinite_bank.hpp>
#include <afmkit/control/loop.hpp>
#include <afmkit/control/oscillator_bank.hpp>
#include <afmkit/control/spectrum.hpp>

namespace {

int run() {
  using namespace afmkit::control;
  const double rotation_hz = 10.0;
  const double omega = 2.0 * std::numbers::pi * rotation_hz;  // Ω [rad/s]
  const double period = 1.0 / rotation_hz;                     // T [s]
  const double plant_rate = 20.0 * omega;                      // γ [1/s]
  const double alpha = 0.1 * omega, beta = -0.1 * omega;       // couplings of eq. (20) [rad/s]

  std::printf("rotation %.4g Hz (T = %.4g ms), static plant gamma = %.4g 1/s, alpha = %.4g rad/s, beta = %.4g rad/s\n",
              rotation_hz, period * 1e3, plant_rate, alpha, beta);
  std::printf("%8s  %14s  %10s  %16s  %6s\n", "N", "tau_c [ms]", "tau_c / T", "crossing [Hz]", "method");

  auto print = [&](const std::string& label, const LoopSpec& loop) {
    const DelayMargin m = delay_margin(loop);
    if (!m.stable_at_reference) {
      std::printf("%8s  not stable without delay\n", label.c_str());
      return m;
    }
    std::printf("%8s  %14.6f  %10.6f  %16.6f  %6s\n", label.c_str(), m.upper * 1e3, m.upper / period,
                m.upper_frequency / (2.0 * std::numbers::pi), m.method.c_str());
    return m;
  };

  // Single oscillator of eqs. (5)-(6): a = 0.5 Ω, b = 0 (closed form E1).
  print("single", LoopSpec(OscillatorBank::single(omega, 0.5 * omega, 0.0, plant_rate), PlantKind::Static,
                           plant_rate, 0.0));
  DelayMargin design{};
  for (int n : {1, 2, 5, 10, 50}) {
    const DelayMargin m = print(std::to_string(n), LoopSpec(OscillatorBank::with_couplings(omega, n, alpha, beta,
                                                                                           plant_rate),
                                                            PlantKind::Static, plant_rate, 0.0));
    if (n == 10) design = m;
  }
  print("infinite", LoopSpec(InfiniteBank(omega, alpha, beta, plant_rate), PlantKind::Static, plant_rate, 0.0));

  // Check N = 10: stable (no root with Re s >= 0) at 0.95 τ_c, unstable at 1.05 τ_c.
  if (!design.stable_at_reference || !std::isfinite(design.upper)) {
    std::printf("error: the N = 10 loop has no finite delay margin\n");
    return 1;
  }
  const LoopSpec loop(OscillatorBank::with_couplings(omega, 10, alpha, beta, plant_rate), PlantKind::Static,
                      plant_rate, 0.0);
  const UnstableCount below = unstable_roots(loop.with_delay(0.95 * design.upper));
  const UnstableCount above = unstable_roots(loop.with_delay(1.05 * design.upper));
  std::printf("N = 10: %d unstable root(s) at tau = 0.95 tau_c, %d at 1.05 tau_c; decay rate at 0.5 tau_c: %.4g 1/s\n",
              below.count, above.count, -spectral_abscissa(loop.with_delay(0.5 * design.upper)));
  if (below.count != 0 || above.count < 2) {
    std::printf("error: the root counts contradict the delay margin\n");
    return 1;
  }
  std::printf("ok\n");
  return 0;
}

}  // namespace

int main() {
  try {
    return run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "delay_margin: %s\n", e.what());
    return 1;
  }
}
