// A sweep the command line does not offer, written with the library: the tapping-mode response against the
// quality factor Q of the cantilever, at a fixed separation and a fixed free amplitude (what an instrument keeps
// when the same cantilever is used in air, in a damping chamber or under active Q control).
//
// For each Q the program
//   1. builds the model in physical units (PhysicalCantilever: k in N/m, f0 in kHz, free amplitude in nm),
//   2. solves the harmonic balance (HB, the first-harmonic approximation of seed-1 eqs. 16-19) at the separation,
//   3. converges the periodic orbit by Newton shooting from the HB solution (exact closed-form flow for the
//      piecewise-linear law used here) and checks its Floquet stability,
//   4. measures the orbit (amplitude, phase, peak force, energy dissipated in the sample per period),
//   5. estimates the sample's dissipation from the amplitude and phase alone, as phase imaging does:
//      the drive's work per period is pi F0 B sin(phase) (only the first harmonic of x takes work from a sinusoidal
//      drive) and the air takes pi k r B^2 / Q from a sinusoidal motion (r = f/f0), so
//      E_phase = pi F0 B sin(phase) - pi k r B^2 / Q,
// and prints one row of a table. Then it checks its results against independent formulas:
//   * far from the sample (no contact) the orbit is the linear oscillator: amplitude = the free amplitude, phase =
//     atan2(r/Q, 1 - r^2), no dissipation in the sample; the drive force is F0 = k A_free sqrt((1 - r^2)^2 + (r/Q)^2);
//   * energy balance: the drive's work per period equals pi F0 B sin(phase) and the energy dissipated (air + sample);
//   * in light tapping (set-point 80 %) HB is close: amplitude within 2 %, phase within 0.02 rad, and closer the
//     higher Q (the motion is more nearly sinusoidal);
//   * E_phase never underestimates the sample's dissipation (it leaves out the air damping of the harmonics 2, 3, ...,
//     which is >= 0) and its relative error falls as Q grows;
// and prints "ok" when all hold.
//
// Units: the model is solved in the normalised units of the papers (time 1/omega_n, lengths nm, forces per unit
// mass); UnitScales converts back: lengths nm, forces nN (x k), energies aJ (x k; 1 N/m * 1 nm^2 = 1 aJ).
// Phases in rad (printed in degrees), with x(t) ~ A + B cos(omega t - phase): 90 deg is the free oscillation at
// resonance; a repulsive contact stiffens the oscillator and lowers it.
//
// Build against the installed library: examples/README.md.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

#include <afmkit/core/version.hpp>
#include <afmkit/impact/force_law.hpp>
#include <afmkit/tapping/harmonic_balance.hpp>
#include <afmkit/tapping/orbit.hpp>
#include <afmkit/tapping/shooting.hpp>
#include <afmkit/tapping/units.hpp>

namespace {

using namespace afmkit::tapping;

constexpr double kPi = std::numbers::pi;
constexpr double kDegrees = 180.0 / kPi;

// The instrument (physical units).
constexpr double kSpringConstant = 40.0;       // k [N/m]
constexpr double kResonanceFrequency = 300.0;  // f0 [kHz]
constexpr double kFreeAmplitude = 20.0;        // A_free [nm], kept for every Q (the drive force follows)
constexpr double kFrequencyRatio = 1.0;        // r = f/f0: driven at resonance
constexpr double kSeparation = 16.0;           // l [nm]: sample surface 16 nm below the rest position (set-point 80 %)
constexpr double kFreeSeparation = 25.0;       // l [nm] beyond the free amplitude: no contact (the linear check)

// The sample: piecewise-linear hysteresis (seed-1 eq. 11) in physical units, gap in nm and force in nN, so the
// stiffnesses are in nN/nm = N/m: 400 N/m while the tip approaches, 320 N/m while it departs (energy is lost
// at every tap: restitution sqrt(320/400) = 0.89).
afmkit::impact::ForceLaw sample_law() { return afmkit::impact::PiecewiseLinearLaw::linear_hysteresis(400.0, 320.0); }

struct Row {
  double quality_factor;
  double drive_force;     // F0 [nN]
  double amplitude;       // B [nm] of the converged orbit
  double phase;           // [rad]
  double hb_amplitude;    // B [nm] of the harmonic balance
  double hb_phase;        // [rad]
  double peak_force;      // [nN]
  double contact_loss;    // energy dissipated in the sample per period [aJ]
  double drive_work;      // work of the drive per period [aJ]
  double dissipated;      // air + sample per period [aJ]
  double floquet_max;     // largest |Floquet multiplier| (< 1: stable)
  bool stable;
};

// The tip state at t = 0 of x(t) = A + B cos(omega t - phase): the HB solution as a starting guess for Newton.
TipState state_of(const HbPoint& hb, double drive_frequency) {
  return {hb.offset + hb.amplitude * std::cos(hb.phase), hb.amplitude * drive_frequency * std::sin(hb.phase)};
}

// One point of the sweep: the orbit at `separation` for quality factor Q (nullopt when Newton fails).
std::optional<Row> solve(double quality_factor, double separation) {
  // The cantilever as the instrument states it; validated (a negative Q would throw InvalidParameter).
  const PhysicalCantilever cantilever(kSpringConstant, kResonanceFrequency, quality_factor, kFreeAmplitude,
                                      kFrequencyRatio);
  const UnitScales units = cantilever.scales();  // model -> nm, nN, aJ
  // The normalised model: cantilever (omega_n = 1, Q), drive (Gamma from the free amplitude, omega = r),
  // the law divided by k (forces per unit mass), and the separation in nm.
  const TappingModel model(cantilever.cantilever(), cantilever.drive(), cantilever.normalised_law(sample_law()),
                           separation);

  // Harmonic balance: every first-harmonic solution at this separation, by increasing amplitude. The largest
  // one on the "+" (or free) branch is the one that continues the free oscillation (the "-" branch is unstable).
  const HarmonicBalance hb(model);
  std::optional<HbPoint> guess;
  for (const HbPoint& p : hb.solutions(separation))
    if (p.branch != HbBranch::Minus) guess = p;
  if (!guess) return std::nullopt;

  // Newton shooting on the one-period stroboscopic map from the HB state (exact closed-form flow of this law):
  // a periodic orbit with its monodromy matrix and Floquet multipliers.
  const std::optional<PeriodicOrbit> orbit = try_shoot(model, state_of(*guess, model.drive.frequency), 1);
  if (!orbit) return std::nullopt;

  // Observables of the orbit, from one simulated period (Fourier coefficients by quadrature between events).
  const OrbitMetrics m = analyse_orbit(model, *orbit);
  return Row{quality_factor,
             model.drive.amplitude * units.force,  // Gamma is a force per unit mass: x k gives nN
             m.amplitude * units.length,
             m.phase,
             guess->amplitude * units.length,
             guess->phase,
             m.peak_force * units.force,
             m.contact_dissipation * units.energy,
             m.drive_work * units.energy,
             m.energy_dissipated() * units.energy,
             orbit->floquet_max,
             orbit->stable};
}

// Prints what failed, with the value found and the value it was compared with.
bool check(bool condition, const char* what, double value, double reference) {
  if (!condition) std::printf("error: %s: %.10g (compared with %.10g)\n", what, value, reference);
  return condition;
}

int run() {
  std::printf("afmkit %s: tapping response against the quality factor\n", afmkit::version);
  std::printf("cantilever k = %g N/m, f0 = %g kHz, free amplitude %g nm at f/f0 = %g; sample 400/320 N/m; "
              "separation %g nm\n\n",
              kSpringConstant, kResonanceFrequency, kFreeAmplitude, kFrequencyRatio, kSeparation);
  std::printf("%6s %8s %9s %8s %9s %8s %7s %8s %9s %9s %8s\n", "Q", "F0", "B_orbit", "phase", "B_HB", "phase_HB",
              "dB/B", "peak F", "E_sample", "E_phase", "|mu|max");
  std::printf("%6s %8s %9s %8s %9s %8s %7s %8s %9s %9s %8s\n", "[-]", "[nN]", "[nm]", "[deg]", "[nm]", "[deg]", "[%]",
              "[nN]", "[aJ]", "[aJ]", "[-]");

  const double r = kFrequencyRatio;
  bool ok = true;
  double previous_hb_error = 1.0, previous_phase_error = 1.0;
  for (const double quality_factor : {30.0, 60.0, 100.0, 200.0, 400.0, 1000.0}) {
    const std::optional<Row> row = solve(quality_factor, kSeparation);
    if (!row) {
      std::printf("error: no periodic orbit at Q = %g\n", quality_factor);
      return 1;
    }
    const double hb_error = (row->amplitude - row->hb_amplitude) / row->amplitude;
    // Phase imaging: the sample's dissipation from B and the phase alone [nN nm = aJ per drive period].
    const double work = kPi * row->drive_force * row->amplitude * std::sin(row->phase);
    const double air = kPi * kSpringConstant * r * row->amplitude * row->amplitude / quality_factor;
    const double phase_estimate = work - air;
    std::printf("%6g %8.4f %9.4f %8.3f %9.4f %8.3f %7.3f %8.4g %9.4g %9.4g %8.5f%s\n", row->quality_factor,
                row->drive_force, row->amplitude, row->phase * kDegrees, row->hb_amplitude, row->hb_phase * kDegrees,
                100.0 * hb_error, row->peak_force, row->contact_loss, phase_estimate, row->floquet_max,
                row->stable ? "" : " unstable");

    ok &= check(row->stable, "Floquet stability (max |mu| < 1)", row->floquet_max, 1.0);
    ok &= check(row->contact_loss > 0, "energy dissipated in the sample [aJ]", row->contact_loss, 0.0);
    // Energy balance: work = pi F0 B sin(phase) = air + sample.
    ok &= check(std::abs(row->drive_work - work) < 1e-6 * work, "drive work [aJ] vs pi F0 B sin(phase)",
                row->drive_work, work);
    ok &= check(std::abs(row->dissipated - work) < 1e-6 * work, "energy dissipated [aJ] vs drive work",
                row->dissipated, work);
    // Light tapping: HB close to the orbit, and closer as Q grows.
    ok &= check(std::abs(hb_error) < 0.02, "orbit amplitude vs HB (relative)", row->amplitude, row->hb_amplitude);
    ok &= check(std::abs(row->phase - row->hb_phase) < 0.02, "orbit phase vs HB [rad]", row->phase, row->hb_phase);
    ok &= check(std::abs(hb_error) < previous_hb_error, "HB error falls with Q", std::abs(hb_error),
                previous_hb_error);
    previous_hb_error = std::abs(hb_error);
    // Phase imaging: never below the true value (it omits the harmonics' air damping, >= 0), closer as Q grows.
    const double phase_error = (phase_estimate - row->contact_loss) / row->contact_loss;
    ok &= check(phase_error > -1e-9, "E_phase >= E_sample [aJ]", phase_estimate, row->contact_loss);
    ok &= check(phase_error < previous_phase_error, "E_phase error falls with Q", phase_error, previous_phase_error);
    previous_phase_error = phase_error;

    // Out of contact: the linear oscillator, whatever Q.
    const std::optional<Row> free = solve(quality_factor, kFreeSeparation);
    const double drive_force = kSpringConstant * kFreeAmplitude * std::hypot(1.0 - r * r, r / quality_factor);
    const double free_phase = std::atan2(r / quality_factor, 1.0 - r * r);
    ok &= check(free.has_value(), "free orbit found", 0.0, 1.0);
    if (free) {
      ok &= check(std::abs(free->drive_force - drive_force) < 1e-12 * drive_force, "drive force F0 [nN]",
                  free->drive_force, drive_force);
      ok &= check(std::abs(free->amplitude - kFreeAmplitude) < 1e-8 * kFreeAmplitude, "free amplitude [nm]",
                  free->amplitude, kFreeAmplitude);
      ok &= check(std::abs(free->phase - free_phase) < 1e-8, "free phase [rad]", free->phase, free_phase);
      ok &= check(free->contact_loss == 0.0, "no sample dissipation out of contact [aJ]", free->contact_loss, 0.0);
    }
  }
  std::printf("\nB: first harmonic of the tip motion; phase: its lag behind the drive force F0 cos(wt); "
              "E_sample: energy taken by the\nsample per drive period; E_phase: the same estimated from B and the "
              "phase alone (phase imaging).\n");
  if (!ok) return 1;
  std::printf("ok\n");
  return 0;
}

}  // namespace

int main() {
  try {
    return run();
  } catch (const std::exception& e) {  // afmkit::InvalidParameter, NumericalFailure, ...
    std::fprintf(stderr, "custom_sweep: %s\n", e.what());
    return 1;
  }
}
