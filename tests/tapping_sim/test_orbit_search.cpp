// find_orbits inside bistable windows: both stable orbits and the saddle between them, for the repulsive–
// attractive law (seed-1 eq. 26, the demo case of docs/commands.md) and the DMT law (docs/units.md). The
// bistability is established independently of find_orbits by plain time simulation with the adaptive integrator
// (no shooting, no continuation): two transients from different initial conditions settle on different orbits,
// and the saddle is shown to separate them (its unstable direction leads to one stable orbit on each side).
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/observer.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/units.hpp"
#include "fixtures.hpp"

namespace afmkit::tapping {
namespace {

using testing::make_model;

// Demo case (seed-1 eq. 26): K_a = 10, K_b = 8, F_a = 0.5, F_b = 1, ω = 0.99, Q = 100, Γ = 0.2.
TappingModel demo_model(double l) { return make_model(10, 8, 0.5, 1, l, 0.99); }

// DMT bistable case (physical units, docs/units.md): k = 40 N/m, f0 = 300 kHz, Q = 400, A_free = 20 nm, drive at
// resonance, E* = 1.5 GPa, R = 20 nm, A_H = 6.4e-20 J, a0 = 0.165 nm. Approach and retract differ for
// l ≈ 16.5 … 18.85 nm (attractive low-amplitude state vs repulsive high-amplitude state).
TappingModel dmt_model(double l) {
  const PhysicalCantilever pc(40.0, 300.0, 400.0, 20.0, 1.0);
  const impact::DmtLaw dmt(1.5, 1.5, 20.0, 6.4e-20, 6.4e-20, 0.165);
  return {pc.cantilever(), pc.drive(), impact::ForceLaw(dmt).scaled(1.0 / 40.0), l};
}

SimulationOptions adaptive_options() {
  SimulationOptions o;
  o.integrator = Integrator::adaptive;
  o.relative_tolerance = 1e-10;
  return o;
}

/// Stroboscopic state after `periods` drive periods of plain adaptive simulation.
TipState run_periods(const TappingModel& m, TipState y, int periods) {
  for (int k = 0; k < periods; ++k) y = simulate(m, 0.0, y, m.period(), adaptive_options()).state;
  return y;
}

/// Quasi-static ramp of the separation (plain adaptive simulation, `hold` periods per separation).
TipState ramp(const TappingModel& base, TipState y, double from, double to, int steps, int hold) {
  for (int k = 0; k <= steps; ++k) y = run_periods(base.with_separation(from + (to - from) * k / steps), y, hold);
  return y;
}

double phase_distance(TipState a, TipState b, double omega) {
  return std::hypot(a.position - b.position, (a.velocity - b.velocity) / omega);
}

/// Index of the orbit of r whose initial state is within tol of y (-1: none).
int orbit_near(const OrbitSearchResult& r, TipState y, double omega, double tol) {
  for (std::size_t i = 0; i < r.orbits.size(); ++i)
    if (phase_distance(r.orbits[i].orbit.initial, y, omega) <= tol) return static_cast<int>(i);
  return -1;
}

/// The search report is consistent: counts per kind, seeds ↔ orbits links both ways.
void expect_consistent_report(const OrbitSearchResult& r) {
  const OrbitSearchReport& rep = r.report;
  int total = 0;
  for (int k = 0; k < seed_kind_count; ++k) {
    total += rep.seeds_by_kind[k];
    EXPECT_LE(rep.converged_by_kind[k], rep.seeds_by_kind[k]);
  }
  EXPECT_EQ(total, static_cast<int>(rep.seeds.size()));
  for (std::size_t i = 0; i < r.orbits.size(); ++i) {
    EXPECT_FALSE(r.orbits[i].seeds.empty());
    for (int s : r.orbits[i].seeds) {
      ASSERT_LT(s, static_cast<int>(rep.seeds.size()));
      const auto& o = rep.seeds[s].orbits;
      EXPECT_NE(std::find(o.begin(), o.end(), static_cast<int>(i)), o.end());
    }
  }
  EXPECT_GT(rep.seeds_by_kind[static_cast<int>(SeedKind::grid)], 0);
  EXPECT_GT(rep.continuation_runs, 0);
  EXPECT_LT(rep.bracket_min, rep.bracket_max);
}

/// Both stable orbits (reached by the two independent transients y_a, y_b) and a saddle separating them.
void expect_bistable_with_saddle(const TappingModel& m, const OrbitSearchResult& r, TipState y_a, TipState y_b,
                                 int settle_periods, double tol) {
  const double omega = m.drive.frequency;
  const double scale = std::hypot(y_a.position, y_a.velocity / omega);
  ASSERT_GT(phase_distance(y_a, y_b, omega), 0.01 * scale) << "the two transients must settle on different orbits";
  const int a = orbit_near(r, y_a, omega, tol * scale), b = orbit_near(r, y_b, omega, tol * scale);
  ASSERT_GE(a, 0) << "find_orbits misses the orbit the first transient settles on";
  ASSERT_GE(b, 0) << "find_orbits misses the orbit the second transient settles on";
  EXPECT_TRUE(r.orbits[a].orbit.stable);
  EXPECT_TRUE(r.orbits[b].orbit.stable);
  // a period-1 saddle whose unstable direction leads to a on one side and to b on the other
  bool separated = false;
  for (const FoundOrbit& f : r.orbits) {
    if (f.orbit.stable || f.orbit.period_multiple != 1 || separated) continue;
    // independently periodic: one adaptive period closes it
    const TipState once = run_periods(m, f.orbit.initial, 1);
    EXPECT_LT(phase_distance(once, f.orbit.initial, omega), 1e-6 * scale);
    const Eigen::EigenSolver<Eigen::Matrix2d> eig(f.orbit.monodromy);
    int k = std::abs(eig.eigenvalues()[0]) > std::abs(eig.eigenvalues()[1]) ? 0 : 1;
    if (std::abs(eig.eigenvalues()[k].imag()) > 0) continue;
    const Eigen::Vector2d v = eig.eigenvectors().col(k).real().normalized();
    int reached[2] = {-1, -1};
    for (int side = 0; side < 2; ++side) {
      const double eps = (side ? -1e-4 : 1e-4) * scale;
      const TipState start{f.orbit.initial.position + eps * v.x(), f.orbit.initial.velocity + eps * v.y()};
      reached[side] = orbit_near(r, run_periods(m, start, settle_periods), omega, tol * scale);
    }
    separated = (reached[0] == a && reached[1] == b) || (reached[0] == b && reached[1] == a);
  }
  EXPECT_TRUE(separated) << "no unstable orbit whose unstable manifold leads to both stable orbits";
}

// Between the HB fold (10.1003) and the time-domain fold (≈ 10.1138) harmonic balance has no contact solution,
// yet the stable contact orbit (the retract branch) and the saddle exist; earlier inside the window as well.
class DemoWindow : public ::testing::TestWithParam<double> {};

TEST_P(DemoWindow, FindsBothStableOrbitsAndTheSaddle) {
  const double l = GetParam();
  const TappingModel m = demo_model(l);
  const OrbitSearchResult r = find_orbits(m);
  expect_consistent_report(r);
  // transient 1: from 97 % of the free oscillation (the amplitude approaches A_free < l from below without
  // reaching the sample; from rest it would overshoot, touch and be captured by the contact orbit)
  const TipState f = free_response_state(m);
  const TipState y_free = run_periods(m, {0.97 * f.position, 0.97 * f.velocity}, 1200);
  // transient 2: the retract — from rest on the sample at l = 8.8 (only the contact orbit exists there), then the
  // separation raised slowly to l
  const TappingModel base = demo_model(8.8);
  TipState y = run_periods(base, {0.0, 0.0}, 600);
  // (near the fold the basin of the contact orbit narrows: steps of 0.005 above l = 9.9)
  const double coarse_end = std::min(l, 9.9);
  y = ramp(base, y, 8.8, coarse_end, static_cast<int>(std::lround((coarse_end - 8.8) / 0.05)), 120);
  if (l > coarse_end) y = ramp(base, y, coarse_end, l, static_cast<int>(std::lround((l - coarse_end) / 0.005)), 120);
  const TipState y_contact = run_periods(m, y, 1200);
  expect_bistable_with_saddle(m, r, y_free, y_contact, 1500, 1e-5);
  if (l > 10.1003) {
    EXPECT_EQ(r.harmonic_balance.size(), 1u);  // beyond the HB fold: HB sees the free branch only
  }
}

INSTANTIATE_TEST_SUITE_P(OrbitSearch, DemoWindow, ::testing::Values(9.6, 10.105, 10.11));

TEST(OrbitSearch, DmtBistableWindowFindsBothStableOrbitsAndTheSaddle) {
  const double l = 17.5;
  const TappingModel m = dmt_model(l);
  const OrbitSearchResult r = find_orbits(m);
  expect_consistent_report(r);
  EXPECT_FALSE(r.harmonic_balance.empty());  // HB for any law (numerical describing functions) seeds the search too
  // transient 1: from rest at l (settles in the repulsive, high-amplitude state)
  const TipState y_rest = run_periods(m, {0.0, 0.0}, 2000);
  // transient 2: the approach — the free oscillation at l = 21 (out of reach of the sample), the separation lowered
  // slowly to l (stays in the attractive, low-amplitude state)
  const TappingModel far = dmt_model(21.0);
  TipState y = free_response_state(far);
  y = ramp(far, y, 21.0, l, 14, 150);
  const TipState y_approach = run_periods(m, y, 2000);
  expect_bistable_with_saddle(m, r, y_rest, y_approach, 2500, 1e-3);
}

TEST(OrbitSearch, RejectsBadOptions) {
  const TappingModel m = demo_model(10.0);
  OrbitSearchOptions o;
  o.grid_phases = 0;
  EXPECT_THROW(find_orbits(m, o), InvalidParameter);
  o = {};
  o.grid_amplitudes = {0.5, std::nan("")};
  EXPECT_THROW(find_orbits(m, o), InvalidParameter);
  o = {};
  o.grid_transient_periods = {24, 12};
  EXPECT_THROW(find_orbits(m, o), InvalidParameter);
  o = {};
  o.bracket_fraction = -0.1;
  EXPECT_THROW(find_orbits(m, o), InvalidParameter);
}

// A grazing contact shorter than one scan step of the closed form (law 10, K = 10, l just below the free
// amplitude 20): the contact must be both entered and left, as the adaptive integrator does. (The closed form
// used to start the contact segment with the gap at +1e-16, so the exit guard looked already crossed and the tip
// stayed "in contact" for the rest of the period.)
TEST(OrbitSearch, ClosedFormResolvesContactShorterThanAScanStep) {
  const TappingModel m = make_model(10, 10, 0, 0, 19.995, 1.0);
  const TipState start{0.0485721216, 19.99976056};
  EventRecorder closed, adapt;
  const auto rc = simulate(m, 0.0, start, m.period(), {}, &closed);
  const auto ra = simulate(m, 0.0, start, m.period(), adaptive_options(), &adapt);
  ASSERT_EQ(adapt.events().size(), 2u);
  ASSERT_EQ(closed.events().size(), 2u);
  EXPECT_NEAR(closed.events()[1].time - closed.events()[0].time, adapt.events()[1].time - adapt.events()[0].time,
              1e-7);
  EXPECT_NEAR(rc.state.position, ra.state.position, 1e-6);
  EXPECT_NEAR(rc.state.velocity, ra.state.velocity, 1e-6);
}

}  // namespace
}  // namespace afmkit::tapping
