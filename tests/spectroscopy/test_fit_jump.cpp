// Where the followed branch ends (a jump), the fit's forward model lands by Newton from the harmonic-balance
// solutions when exactly one stable orbit exists there; an instrument (and the sweep engine) lets the transient
// settle. Checked against the transient itself: the orbit after the jump is the one the transient settles on
// (docs/fitting.md#model).
#include <gtest/gtest.h>

#include "afmkit/impact/law_registry.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"

using namespace afmkit;
using namespace afmkit::spectroscopy;

TEST(FitJump, LandsWhereTheTransientSettles) {
  // DMT + vdW, Q = 200, A0 = 20 nm: on approach the attractive branch ends near 15.26 nm
  const double q = 200.0;
  const tapping::PhysicalCantilever pc(40.0, 300.0, q, 20.0, 1.0);
  impact::LawArguments args;
  args.values = {{"effective_modulus", 1.0}, {"tip_radius", 10.0}, {"hamaker", 2e-19}};
  const tapping::TappingModel base(pc.cantilever(), pc.drive(),
                                   pc.normalised_law(impact::LawRegistry::builtin().build("dmt", args)), 0.0);
  // the branch from the free response at 22 nm, followed down to 15 nm: it ends before
  const tapping::TappingModel start = base.with_separation(22.0);
  const auto free = tapping::try_shoot(start, tapping::free_response_state(start), 1);
  ASSERT_TRUE(free && free->stable);
  tapping::PeriodicOrbit from = *free;
  from.separation = 22.0;
  const tapping::SweepOptions so;
  const tapping::BranchFollow f = tapping::follow_stable_branch(base, from, 15.0, so);
  ASSERT_FALSE(f.reached);
  ASSERT_GT(f.last.separation, 15.0);
  // the transient from the last stable orbit, at 15 nm
  const tapping::TappingModel at = base.with_separation(15.0);
  const tapping::TransientOutcome t = tapping::settle(at, f.last.initial, so.transient, so.shooting);
  ASSERT_TRUE(t.orbit);
  const tapping::OrbitMetrics settled = tapping::analyse_orbit(at, *t.orbit);

  FitSettings s;
  s.spring_constant = 40.0;
  s.resonance_frequency = 300e3;
  s.quality_factor = q;
  s.free_amplitude = 20e-9;
  FitOptions o;
  o.law_values = {{"effective_modulus", 1e9}, {"tip_radius", 10e-9}, {"hamaker", 2e-19}};
  o.integrator_tolerance = 1e-10;
  o.shooting_tolerance = 1e-11;
  const AmPrediction p = predict_am_curve({22e-9, 20e-9, 18e-9, 16e-9, 15e-9}, s, o);
  EXPECT_FALSE(p.jumped[3]);
  EXPECT_TRUE(p.jumped[4]);
  EXPECT_TRUE(p.contact[4]);
  EXPECT_NEAR(p.amplitude[4], settled.amplitude * 1e-9, 1e-16);  // 1e-7 nm
  EXPECT_NEAR(p.phase[4], settled.phase, 1e-7);
  // and far from the jump's start: a different orbit (the jump is real: more than 5 % of A0 in amplitude)
  const tapping::OrbitMetrics before = tapping::analyse_orbit(base.with_separation(f.last.separation), f.last);
  EXPECT_GT(std::abs(before.amplitude - settled.amplitude), 1.0);
}
