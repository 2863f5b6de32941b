// Jumps of the instrument sweep are located where the followed branch ceases to be stable, whatever the grid.
// The case (docs/commands.md#afmkit-tapping-sweep--amplitudedistance-curves): a DMT approach–retract close to the
// sample, where the followed orbit loses stability inside a grid step — the free branch through a multiplier at
// −1 on approach, the contact branch in a period-doubling cascade on retract. The sweep used to report jumps that
// depended on the grid (25 points: one at 0.0 nm; 60: none; 241: three each way at grid points). The reference
// here is independent of the sweep's sub-stepping: a brute-force walk in fixed steps of l, each orbit shot from the
// previous one, its Floquet multipliers computed, until the orbit is no longer stable.
#include <cmath>
#include <complex>
#include <map>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/force_law.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::tapping {
namespace {

// k = 40 N/m, f0 = 300 kHz, Q = 400, A_free = 10 nm at resonance, DMT: R = 10 nm, E* = 1 GPa, A_H = 1e-19 J,
// a0 = 0.165 nm; lengths in nm (docs/units.md).
TappingModel dmt_case(double l) {
  const PhysicalCantilever pc(40.0, 300.0, 400.0, 10.0, 1.0);
  const impact::DmtLaw dmt(1.0, 1.0, 10.0, 1e-19, 1e-19, 0.165);
  return {pc.cantilever(), pc.drive(), pc.normalised_law(impact::ForceLaw(dmt)), l};
}

SweepOptions options() {
  SweepOptions o;
  o.harmonic_balance = false;   // not compared here
  o.transient.max_periods = 4000;  // the same jumps as with 20000 (measured), 4× faster in the non-periodic window
  return o;
}

/// Whether a jump lands on the period-doubled orbit of the one it leaves (n -> 2n): where it lands is then decided
/// next to the orbit it leaves. Any other landing (another period, or a response that does not settle) is the end
/// of a chaotic transient whose length depends on the state it starts from to rounding: on retract, where the
/// period-4 orbit of the cascade loses stability (l ≈ 0.2890 nm), 21 transients from its last stable orbit with x
/// moved by up to 1e-8 (relative) settle on the period-3 orbit after 312 to more than 4000 periods (3 of 21 not
/// within the 4000 periods of options(), all 21 within 20000: measured), so the same jump is reported landing on
/// the period-3 orbit or on a response that did not settle, depending on the orbit's last digits.
bool lands_by_doubling(const SweepJump& j) {
  return j.landed_periodic && j.to.period_multiple == 2 * j.from.period_multiple;
}

/// The jumps of one direction up to and including the first that does not land by period doubling (beyond it the
/// response went through a chaotic transient: where it settles depends on the transient, as on an instrument), in
/// sweep order. Their locations are the grid's business; the landing of the last one is not.
std::vector<SweepJump> deterministic_jumps(const SweepResult& r, SweepDirection d) {
  std::vector<SweepJump> out;
  for (const SweepJump& j : r.jumps) {
    if (j.direction != d) continue;
    out.push_back(j);
    if (!lands_by_doubling(j) || !j.located) break;
  }
  return out;
}

/// Brute force: from the stable orbit `from`, shoot the orbit at l = from.separation + k·step (k = 1, 2, …, Newton
/// from the previous orbit) until it is not found or not stable; returns the first such l (nullopt: never, within
/// `steps`). The multipliers of the last stable orbit go to `last`.
std::optional<double> brute_force_end(const TappingModel& base, PeriodicOrbit from, double step, int steps,
                                      PeriodicOrbit& last) {
  last = from;
  for (int k = 1; k <= steps; ++k) {
    const double l = from.separation + k * step;
    std::optional<PeriodicOrbit> o;
    try {
      o = try_shoot(base.with_separation(l), last.initial, last.period_multiple, {});
    } catch (const NumericalFailure&) {
      o.reset();
    }
    if (!o || !o->stable || o->period_multiple != last.period_multiple) return l;
    last = *o;
  }
  return std::nullopt;
}

// The instrument sweeps of the three grids, each computed once per process and only when a test asks for it (each
// test runs in its own process under ctest: the brute-force tests need only the 25- and 60-point sweeps).
const SweepResult& grid_sweep(int points) {
  static std::map<int, SweepResult> sweeps;
  auto it = sweeps.find(points);
  if (it == sweeps.end())
    it = sweeps.emplace(points, sweep_instrument(dmt_case(12.0), 0.0, 12.0, points, options())).first;
  return it->second;
}
constexpr int kGrids[] = {25, 60, 241};

TEST(LocatedJumps, TheSameJumpsOnEveryGrid) {
  const double tol = options().jump_tolerance * dmt_case(12.0).free_amplitude();  // 1e-4 nm
  for (SweepDirection d : {SweepDirection::approach, SweepDirection::retract}) {
    const auto reference = deterministic_jumps(grid_sweep(241), d);
    ASSERT_FALSE(reference.empty()) << direction_name(d);
    for (int points : {25, 60}) {
      const auto jumps = deterministic_jumps(grid_sweep(points), d);
      ASSERT_EQ(jumps.size(), reference.size()) << direction_name(d) << ", grid of " << points << " points";
      for (std::size_t i = 0; i < jumps.size(); ++i) {
        EXPECT_TRUE(jumps[i].located);
        EXPECT_LE(jumps[i].tolerance, tol);
        EXPECT_NEAR(jumps[i].separation, reference[i].separation, 2.0 * tol) << direction_name(d) << " jump " << i;
        EXPECT_EQ(lands_by_doubling(jumps[i]), lands_by_doubling(reference[i])) << direction_name(d) << " jump " << i;
      }
    }
  }
  // every jump is listed per direction, and each grid row after a jump is marked
  for (int points : kGrids) {
    const SweepResult& r = grid_sweep(points);
    std::size_t approach = 0;
    for (const SweepJump& j : r.jumps) approach += j.direction == SweepDirection::approach;
    EXPECT_EQ(r.approach_jumps.size(), approach);
    EXPECT_EQ(r.retract_jumps.size(), r.jumps.size() - approach);
    for (const SweepJump& j : r.jumps) {
      if (!j.located) continue;
      const auto& side = j.direction == SweepDirection::approach ? r.approach : r.retract;
      const bool up = j.direction == SweepDirection::retract;
      const SweepPoint* next = nullptr;
      for (const SweepPoint& p : side)
        if (up ? p.separation >= j.separation : p.separation <= j.separation) {
          next = &p;
          break;
        }
      ASSERT_NE(next, nullptr);
      EXPECT_TRUE(next->jumped) << "row at " << next->separation << " after the jump at " << j.separation;
    }
  }
}

/// The last grid point of `side` before separation l in sweep order (the orbit followed into the jump).
const SweepPoint& row_before(const std::vector<SweepPoint>& side, double l) {
  const SweepPoint* before = &side.front();
  for (const SweepPoint& p : side) {
    if (side.front().separation > side.back().separation ? p.separation <= l : p.separation >= l) break;
    before = &p;
  }
  return *before;
}

TEST(LocatedJumps, ApproachJumpWhereTheFreeBranchLosesStabilityByBruteForce) {
  const TappingModel base = dmt_case(12.0);
  const double tol = options().jump_tolerance * base.free_amplitude();
  const SweepJump j = deterministic_jumps(grid_sweep(25), SweepDirection::approach).front();
  EXPECT_LT(j.separation, 0.5);
  // the free (non-touching) period-1 orbit of the grid point before, walked down in steps of 1e-4 nm
  const SweepPoint& before = row_before(grid_sweep(25).approach, j.separation);
  ASSERT_TRUE(before.orbit.stable);
  PeriodicOrbit last;
  const double step = 1e-4;
  const int steps = static_cast<int>((before.separation - j.separation) / step) + 100;
  const auto end = brute_force_end(base, before.orbit, -step, steps, last);
  ASSERT_TRUE(end.has_value());
  EXPECT_NEAR(j.separation, *end + 0.5 * step, tol + step);
  // it loses stability near −1 (the pair of multipliers, close to −1, leaves the unit circle there)
  const auto& m = last.floquet_multipliers;
  EXPECT_LT(std::max(m[0].real(), m[1].real()), -0.9) << m[0] << " " << m[1];
}

TEST(LocatedJumps, FirstRetractJumpIsAPeriodDoublingByBruteForce) {
  const TappingModel base = dmt_case(12.0);
  const double tol = options().jump_tolerance * base.free_amplitude();
  const SweepJump j = deterministic_jumps(grid_sweep(60), SweepDirection::retract).front();
  // the contact orbit of the grid point before, walked up in steps of 1e-4 nm
  const SweepPoint& before = row_before(grid_sweep(60).retract, j.separation);
  ASSERT_TRUE(before.orbit.stable);
  PeriodicOrbit last;
  const double step = 1e-4;
  const int steps = static_cast<int>((j.separation - before.separation) / step) + 100;
  const auto end = brute_force_end(base, before.orbit, step, steps, last);
  ASSERT_TRUE(end.has_value());
  EXPECT_NEAR(j.separation, *end - 0.5 * step, tol + step);
  // multipliers close to −1: period doubling, and the orbit landed on has twice the period
  const auto& m = last.floquet_multipliers;
  EXPECT_LT(std::max(m[0].real(), m[1].real()), -0.9) << m[0] << " " << m[1];
  EXPECT_EQ(j.to.period_multiple, 2 * j.from.period_multiple);
}

}  // namespace
}  // namespace afmkit::tapping
