// Continuation and instrument sweeps in a parameter other than the separation (docs/theory-tapping.md#parameter-
// continuation): the drive frequency without contact against the linear resonance curve in closed form; with
// contact, folds in the drive frequency and in a law parameter are the folds of the separation continuation at that
// frequency / law value (the same saddle-node orbit found from two parameters); jumps of the down / up sweeps at the
// folds.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <optional>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/parameter.hpp"
#include "afmkit/tapping/sweep.hpp"

namespace afmkit::tapping {
namespace {

constexpr double kPcQuality = 100.0;
constexpr double kPcDrive = 0.2;  // Γ (ω_n = 1): free amplitude 20 at resonance

TappingModel pc_model(double separation, double omega = 1.0, double f_a = 1.0, double f_b = 2.0) {
  return {Cantilever(1.0, kPcQuality), Drive(kPcDrive, omega),
          impact::ForceLaw(impact::PiecewiseLinearLaw(10.0, 8.0, f_a, f_b)), separation};
}

/// The departure adhesion F_b of the attractive law (seed-1 eq. 26) as the swept parameter.
SweepParameter pc_departure_adhesion() {
  return {"departure_adhesion", [](const TappingModel& base, double f_b) {
            return TappingModel(base.cantilever, base.drive,
                                impact::ForceLaw(impact::PiecewiseLinearLaw(10.0, 8.0, 1.0, f_b)), base.separation);
          }};
}

ContinuationOptions pc_options() {
  ContinuationOptions o;
  o.harmonic_balance = false;
  return o;
}

/// The folds within 0.25 of model.separation of the separation continuation of `model` through an orbit next to
/// `guess`: Newton from guess's state at separation ± 0.05 (away from the fold, where Newton converges; only one side
/// has orbits next to a saddle-node), continued over separation ± 0.5 both ways.
std::vector<ContinuationFold> pc_separation_folds(const TappingModel& model, const PeriodicOrbit& guess) {
  const double l = model.separation;
  ContinuationOptions o = pc_options();
  o.analyse_points = false;
  for (double dl : {0.05, -0.05}) {
    const std::optional<PeriodicOrbit> start = try_shoot(model.with_separation(l + dl), guess.initial, 1);
    if (!start) continue;
    std::vector<ContinuationFold> folds;
    for (bool up : {true, false}) {
      const ContinuationResult c = continue_orbits(model, *start, l - 0.5, l + 0.5, up, o);
      for (const ContinuationFold& f : c.folds)
        if (std::abs(f.separation - l) < 0.25 &&
            std::none_of(folds.begin(), folds.end(), [&](const auto& g) { return std::abs(g.separation - f.separation) < 1e-6; }))
          folds.push_back(f);
    }
    return folds;
  }
  return {};
}

// Without contact the orbits are the linear oscillator's: A(ω) = Γ/|ω_n² − ω² + 2iξω_nω|, phase lag
// φ = arg(ω_n² − ω² + 2iξω_nω) (docs/conventions.md), to rounding over the whole resonance curve.
TEST(ParameterContinuation, DriveFrequencyWithoutContactIsTheLinearResonanceCurve) {
  const TappingModel base = pc_model(1000.0);  // far above any amplitude: never in contact
  ContinuationOptions o = pc_options();
  o.tolerance = 1e-14;  // measured: 3e-14 in amplitude, 3e-13 in phase (2e-9 with the default 1e-10)
  const ContinuationResult c = sweep_continuation(base, SweepParameter::drive_frequency(), 0.9, 1.1, o);
  EXPECT_EQ(c.stop_reason, "left range");
  EXPECT_TRUE(c.folds.empty());
  ASSERT_GT(c.points.size(), 20u);
  double worst_amplitude = 0, worst_phase = 0, lowest = 2, highest = 0;
  for (const SweepPoint& p : c.points) {
    const double w = p.parameter;
    const std::complex<double> d(1.0 - w * w, 2.0 * (0.5 / kPcQuality) * w);
    worst_amplitude = std::max(worst_amplitude, std::abs(p.metrics.amplitude / (kPcDrive / std::abs(d)) - 1.0));
    worst_phase = std::max(worst_phase, std::abs(p.metrics.phase / std::arg(d) - 1.0));
    EXPECT_TRUE(p.orbit.stable);
    EXPECT_EQ(p.separation, 1000.0);
    lowest = std::min(lowest, w);
    highest = std::max(highest, w);
  }
  char measured[96];
  std::snprintf(measured, sizeof measured, "amplitude %.3g, phase %.3g", worst_amplitude, worst_phase);
  RecordProperty("worst_relative_errors", measured);
  EXPECT_LE(worst_amplitude, 1e-12);
  EXPECT_LE(worst_phase, 1e-12);
  EXPECT_LT(lowest, 0.9 + 1e-9);  // the whole range, resonance included
  EXPECT_GT(highest, 1.1 - 0.01);
}

// The down and up sweeps without contact: no jump, every row on the resonance curve, and so is the harmonic balance
// beside each row (evaluated at each row's own drive frequency: exact for the linear oscillator).
TEST(ParameterContinuation, DriveFrequencySweepWithoutContactHasNoJumps) {
  SweepOptions o;
  const SweepResult r = sweep_instrument(pc_model(1000.0), SweepParameter::drive_frequency(), 0.95, 1.05, 11, o);
  EXPECT_TRUE(r.jumps.empty());
  ASSERT_EQ(r.approach.size(), 11u);
  EXPECT_EQ(r.approach.front().parameter, 1.05);  // down first
  EXPECT_EQ(r.retract.back().parameter, 1.05);
  for (const auto* side : {&r.approach, &r.retract})
    for (const SweepPoint& p : *side) {
      const double w = p.parameter;
      const double exact = kPcDrive / std::abs(std::complex<double>(1.0 - w * w, w / kPcQuality));
      EXPECT_NEAR(p.metrics.amplitude, exact, 1e-9 * exact);
      EXPECT_EQ(p.hb_solutions, 1);
      EXPECT_NEAR(p.hb_amplitude, exact, 1e-9 * exact);
    }
}

// With contact (attractive law, l = 14): each fold of the frequency continuation is a fold of the separation
// continuation at that frequency, at l = 14 (the same saddle-node orbit from two parameters); the down / up sweeps
// jump where the continuation has a fold or where the free amplitude reaches the sample (grazing).
// (The range starts above the corner at ω ≈ 0.9949 where the contact branch turns non-smoothly.)
TEST(ParameterContinuation, DriveFrequencyFoldsAreTheSeparationFolds) {
  const double l = 14.0, w_min = 0.997, w_max = 1.05;
  const TappingModel base = pc_model(l);
  const SweepParameter frequency = SweepParameter::drive_frequency();
  ContinuationOptions o = pc_options();
  // folds are located by cubic Hermite interpolation of ω(s) between two points: with steps of 0.05 (scaled
  // arclength) to ~2e-8 in ω here, ~5e-5 in l (measured: 7e-6 in ω, 1.7e-2 in l with the default 0.2; 1e-6 in l
  // with 0.02)
  o.max_step = 0.05;
  const ContinuationResult c = sweep_continuation(base, frequency, w_min, w_max, o);
  ASSERT_EQ(c.folds.size(), 2u) << c.stop_reason;
  for (const ContinuationFold& f : c.folds) {
    const SweepPoint& at = c.points.at(f.point);
    EXPECT_GT(at.metrics.contact_fraction, 0.0);
    const std::vector<ContinuationFold> folds = pc_separation_folds(frequency.at(base, f.parameter), at.orbit);
    ASSERT_EQ(folds.size(), 1u) << "frequency fold at " << f.parameter;
    EXPECT_NEAR(folds[0].separation, l, 5e-4) << "frequency fold at " << f.parameter;
  }

  // grazing: Γ/|1 − ω² + iω/Q| = l, a quadratic in u = ω²: u² − (2 − 1/Q²)u + 1 − (Γ/l)² = 0
  const double b = 2.0 - 1.0 / (kPcQuality * kPcQuality), c0 = 1.0 - (kPcDrive / l) * (kPcDrive / l);
  const double root = std::sqrt(b * b / 4 - c0);
  std::vector<double> edges{std::sqrt(b / 2 - root), std::sqrt(b / 2 + root)};
  for (const ContinuationFold& f : c.folds) edges.push_back(f.parameter);
  SweepOptions so;
  so.harmonic_balance = false;
  const SweepResult r = sweep_instrument(base, frequency, w_min, w_max, 21, so);
  ASSERT_GE(r.approach_jumps.size(), 1u);
  ASSERT_GE(r.retract_jumps.size(), 1u);
  int located = 0;
  for (const SweepJump& j : r.jumps) {
    // (below grazing the tip lands on a non-periodic response first; where it settles from there is known to the
    // transient sub-step only: not an edge of a branch)
    if (!j.located) continue;
    ++located;
    EXPECT_LE(j.tolerance, so.jump_tolerance * w_max * (1 + 1e-12));  // jump_tolerance·max|p|
    double nearest = 1e300;
    for (double e : edges) nearest = std::min(nearest, std::abs(e - j.parameter));
    EXPECT_LE(nearest, 1e-4) << direction_name(j.direction) << " jump at " << j.parameter;
  }
  EXPECT_GE(located, 3);  // down: grazing and the fold at ω ≈ 1.0024; up: the fold at ω ≈ 1.0311
}

// A law parameter (the departure adhesion F_b): the same check at l = 17.
TEST(ParameterContinuation, LawParameterFoldsAreTheSeparationFolds) {
  const double l = 17.0;
  const TappingModel base = pc_model(l);
  const SweepParameter adhesion = pc_departure_adhesion();
  const ContinuationResult c = sweep_continuation(base, adhesion, 2.0, 5.0, pc_options());
  ASSERT_EQ(c.folds.size(), 2u) << c.stop_reason;
  for (const ContinuationFold& f : c.folds) {
    const std::vector<ContinuationFold> folds =
        pc_separation_folds(adhesion.at(base, f.parameter), c.points.at(f.point).orbit);
    ASSERT_EQ(folds.size(), 1u) << "adhesion fold at " << f.parameter;
    EXPECT_NEAR(folds[0].separation, l, 2e-3) << "adhesion fold at " << f.parameter;
  }
}

// A range the model refuses beyond its end (F_b below F_a = 1) stops the continuation at the end of the range, not
// with a failure; a start outside the range is refused naming the parameter.
TEST(ParameterContinuation, RangeEnds) {
  const TappingModel base = pc_model(17.0);
  const ContinuationResult c = sweep_continuation(base, pc_departure_adhesion(), 1.0, 1.5, pc_options());
  EXPECT_EQ(c.stop_reason, "left range");
  try {
    (void)sweep_continuation(base, pc_departure_adhesion(), 1.5, 1.0, pc_options());
    ADD_FAILURE() << "reversed range accepted";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "departure_adhesion_min");
  }
}

}  // namespace
}  // namespace afmkit::tapping
