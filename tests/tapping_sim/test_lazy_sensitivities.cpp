// Sensitivities only where Newton needs them (issue 28 §1): try_shoot_near converges on the map without them and
// integrates them at the converged orbit (its monodromy is the map's derivative there, checked by central
// differences of the map), and a sweep with lazy sensitivities is the eager sweep (orbits, stability, jumps).
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"
#include "fixtures.hpp"

namespace afmkit::tapping {
namespace {

// pyDAMPF's DMT + vdW problem (k = 40 N/m, f0 = 300 kHz, Q = 400, A_free = 10 nm, R = 10 nm, E* = 1 GPa)
TappingModel lazy_dmt_model(double separation) {
  const PhysicalCantilever cantilever(40.0, 300.0, 400.0, 10.0, 1.0);
  const impact::DmtLaw dmt(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165);
  return {cantilever.cantilever(), cantilever.drive(), cantilever.normalised_law(dmt), separation};
}

// The adaptive map is smooth only to its tolerance and M − I is ill-conditioned at Q = 400 (multipliers near the
// unit circle): two Newton paths agree to (M − I)⁻¹ times that, so both run tight here.
ShootingOptions lazy_tight() {
  ShootingOptions o;
  o.tolerance = 1e-12;
  o.simulation.relative_tolerance = 1e-13;
  o.simulation.absolute_tolerance = 1e-14;
  return o;
}

// Central differences of the map (sensitivities off) at `at`: an independent monodromy.
Eigen::Matrix2d lazy_difference_monodromy(const TappingModel& model, TipState at) {
  SimulationOptions o;
  o.relative_tolerance = 1e-13;
  o.absolute_tolerance = 1e-15;
  Eigen::Matrix2d m;
  const double hx = 1e-5 * std::max(1.0, std::abs(at.position)), hv = 1e-5 * std::max(1.0, std::abs(at.velocity));
  for (int c = 0; c < 2; ++c) {
    TipState plus = at, minus = at;
    (c == 0 ? plus.position : plus.velocity) += c == 0 ? hx : hv;
    (c == 0 ? minus.position : minus.velocity) -= c == 0 ? hx : hv;
    const TipState p = simulate(model, 0.0, plus, model.period(), o).state;
    const TipState q = simulate(model, 0.0, minus, model.period(), o).state;
    m.col(c) = Eigen::Vector2d(p.position - q.position, p.velocity - q.velocity) / (2.0 * (c == 0 ? hx : hv));
  }
  return m;
}

TEST(LazySensitivities, ShootNearFindsTheOrbitWithTheMonodromyAtIt) {
  const auto check = [](const TappingModel& near_model, const TappingModel& model, const char* what) {
    SCOPED_TRACE(what);
    const PeriodicOrbit near = shoot(near_model, free_response_state(near_model), 1);
    ASSERT_GT(near.stats.impacts, 0);
    const auto lazy = try_shoot_near(model, near.initial, near, lazy_tight());
    const auto eager = try_shoot(model, near.initial, 1, lazy_tight());
    ASSERT_TRUE(lazy && eager);
    const double scale = std::hypot(eager->initial.position, eager->initial.velocity);
    EXPECT_LT(std::hypot(lazy->initial.position - eager->initial.position,
                         lazy->initial.velocity - eager->initial.velocity),
              1e-9 * scale);
    // the monodromy is the derivative of the map at the converged orbit, not the Broyden estimate
    const Eigen::Matrix2d fd = lazy_difference_monodromy(model, lazy->initial);
    EXPECT_LT((lazy->monodromy - fd).norm(), 1e-5 * fd.norm()) << lazy->monodromy << "\n" << fd;
    EXPECT_LT((lazy->monodromy - eager->monodromy).norm(), 1e-6 * fd.norm());
    EXPECT_NEAR(lazy->floquet_max, eager->floquet_max, 1e-7);
    EXPECT_EQ(lazy->stable, eager->stable);
  };
  check(lazy_dmt_model(6.0), lazy_dmt_model(5.9), "DMT + vdW, adaptive");
  check(testing::attractive_model(17.0), testing::attractive_model(16.9), "attractive hysteresis, closed form");
}

// A guess sent straight to the run with sensitivities (evaluate_guess false, as a sweep does where the last guess
// converged): at the orbit it is that one run (no iteration) with the monodromy there; off the orbit, Newton goes
// on from that run's step to the same orbit.
TEST(LazySensitivities, GuessSentStraightToTheSensitivityRunIsTheOrbit) {
  const TappingModel near_model = lazy_dmt_model(6.0), model = lazy_dmt_model(5.9);
  const PeriodicOrbit near = shoot(near_model, free_response_state(near_model), 1);
  const auto eager = try_shoot(model, near.initial, 1, lazy_tight());
  ASSERT_TRUE(eager);
  const double scale = std::hypot(eager->initial.position, eager->initial.velocity);
  const auto distance = [&](const PeriodicOrbit& o) {
    return std::hypot(o.initial.position - eager->initial.position, o.initial.velocity - eager->initial.velocity);
  };
  const auto at = try_shoot_near(model, eager->initial, near, lazy_tight(), false);
  ASSERT_TRUE(at);
  EXPECT_EQ(at->iterations, 0);
  EXPECT_LT(distance(*at), 1e-9 * scale);
  const Eigen::Matrix2d fd = lazy_difference_monodromy(model, at->initial);
  EXPECT_LT((at->monodromy - fd).norm(), 1e-5 * fd.norm());
  TipState off = eager->initial;
  off.position += 1e-4 * scale;
  const auto from_off = try_shoot_near(model, off, near, lazy_tight(), false);
  ASSERT_TRUE(from_off);
  EXPECT_GE(from_off->iterations, 1);
  EXPECT_LT(distance(*from_off), 1e-9 * scale);
  EXPECT_LT((from_off->monodromy - fd).norm(), 1e-5 * fd.norm());
  EXPECT_EQ(from_off->stable, eager->stable);
}

// The lazy sweep `a` of `model` against the eager one: the same jumps, amplitudes to 1e-8, stability, jump flags.
void lazy_compare_sweeps(const TappingModel& model, double l_min, double l_max, int points, SweepResult& a) {
  SweepOptions eager;
  eager.shooting = lazy_tight();
  eager.parallel = false;
  eager.harmonic_balance = false;
  eager.lazy_sensitivities = false;
  SweepOptions lazy = eager;
  lazy.lazy_sensitivities = true;
  a = sweep_instrument(model, l_min, l_max, points, lazy);
  const SweepResult b = sweep_instrument(model, l_min, l_max, points, eager);
  ASSERT_EQ(a.approach_jumps.size(), b.approach_jumps.size());
  ASSERT_EQ(a.retract_jumps.size(), b.retract_jumps.size());
  for (std::size_t k = 0; k < a.approach_jumps.size(); ++k)
    EXPECT_NEAR(a.approach_jumps[k], b.approach_jumps[k], 1e-4 * model.free_amplitude());
  for (std::size_t k = 0; k < a.retract_jumps.size(); ++k)
    EXPECT_NEAR(a.retract_jumps[k], b.retract_jumps[k], 1e-4 * model.free_amplitude());
  for (const auto& [x, y] : {std::pair(&a.approach, &b.approach), std::pair(&a.retract, &b.retract)}) {
    ASSERT_EQ(x->size(), y->size());
    for (std::size_t k = 0; k < x->size(); ++k) {
      EXPECT_NEAR((*x)[k].metrics.amplitude, (*y)[k].metrics.amplitude, 1e-8 * (*y)[k].metrics.amplitude)
          << "l = " << (*y)[k].separation;
      EXPECT_EQ((*x)[k].orbit.stable, (*y)[k].orbit.stable);
      EXPECT_EQ((*x)[k].jumped, (*y)[k].jumped);
    }
  }
}

TEST(LazySensitivities, SweepIsTheEagerSweep) {
  SweepResult loop, dmt;
  {
    SCOPED_TRACE("hysteresis loop");  // jumps on approach and on retract (the demo's case)
    lazy_compare_sweeps(testing::make_model(10, 8, 0.5, 1, 10.0, 0.99), 8.8, 10.4, 33, loop);
  }
  EXPECT_FALSE(loop.approach_jumps.empty());
  EXPECT_FALSE(loop.retract_jumps.empty());
  SCOPED_TRACE("DMT + vdW");
  lazy_compare_sweeps(lazy_dmt_model(10.0), 4.0, 10.0, 13, dmt);
  EXPECT_EQ(dmt.approach.size(), 13u);
}

// On a coarse grid (the spacing of a 50-point sweep over 2 … 10 nm) Newton starts from the Hermite polynomial
// through the orbits behind and their slopes (sweep.cpp, starting_guess): on the smooth stretch of the branch
// (4 … 8 nm, touching) the guess is a few tolerances off, and Newton needs one Broyden step on the cheap map at most
// before the run with sensitivities (from the quadratic through one orbit behind, as before, the guess was ~1e-6
// off: two steps at every point); the amplitudes are those of a sweep at tolerance 1e-13 to 1e-8.
TEST(LazySensitivities, CoarseGridGuessesFromTheBranchHistoryNeedOneStepAtMost) {
  SweepOptions o;
  o.parallel = false;
  o.harmonic_balance = false;
  o.retract = false;
  SweepOptions tight = o;
  o.shooting.tolerance = o.shooting.simulation.relative_tolerance = 1e-10;
  o.shooting.simulation.absolute_tolerance = 1e-11;
  tight.shooting.tolerance = tight.shooting.simulation.relative_tolerance = 1e-13;
  tight.shooting.simulation.absolute_tolerance = 1e-14;
  const double spacing = 8.0 / 49.0;  // nm
  const int points = 25;
  const TappingModel model = lazy_dmt_model(10.0);
  const SweepResult r = sweep_instrument(model, 4.0, 4.0 + (points - 1) * spacing, points, o);
  const SweepResult reference = sweep_instrument(model, 4.0, 4.0 + (points - 1) * spacing, points, tight);
  ASSERT_EQ(r.approach.size(), reference.approach.size());
  int iterations = 0;
  for (std::size_t k = 0; k < r.approach.size(); ++k) {
    const SweepPoint& p = r.approach[k];
    EXPECT_TRUE(p.orbit.stable && !p.jumped) << "l = " << p.separation;
    EXPECT_NEAR(p.metrics.amplitude, reference.approach[k].metrics.amplitude,
                1e-8 * reference.approach[k].metrics.amplitude) << "l = " << p.separation;
    if (k >= 3) iterations += p.orbit.iterations;  // (the first points have less history behind)
  }
  EXPECT_LE(iterations, 1.4 * (points - 3)) << "Broyden iterations over " << points - 3 << " points";
}

}  // namespace
}  // namespace afmkit::tapping
