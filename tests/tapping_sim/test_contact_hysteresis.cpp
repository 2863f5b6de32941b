// Contact-aware hysteresis (docs/force-laws.md#hysteresis): a measured curve whose retract branch carries an
// adhesion neck up to +14 nm dissipates only after the tip reached the contact gap. Checked against independent
// computations: the conservative (approach-only) law, a Gauss–Legendre quadrature of H_a − H_b over the visited
// range, finite differences of the stroboscopic map, and a long time simulation.
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>
#include <vector>

#include <boost/math/quadrature/gauss.hpp>
#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/tapping/observer.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/system.hpp"
#include "afmkit/tapping/units.hpp"
#include "contact_curve.hpp"

using namespace afmkit;
using afmkit::impact::Hysteresis;

namespace {

// the cantilever of the outside report (k = 1.18 N/m, f0 = 23.3 kHz, Q = 139, A0 = 20 nm) and a stiff one
const tapping::PhysicalCantilever kSoft(1.1841, 23.251, 139.13, 20.0, 1.0);
const tapping::PhysicalCantilever kStiff(40.0, 300.0, 400.0, 10.0, 1.0);  // held by the neck once it touched
const tapping::PhysicalCantilever kTap(40.0, 300.0, 400.0, 20.0, 1.0);    // taps: pulls off every cycle

tapping::TappingModel model(const tapping::PhysicalCantilever& pc, const impact::ForceCurve& curve, Hysteresis h,
                            double separation) {
  return {pc.cantilever(), pc.drive(), pc.normalised_law(impact::make_law<impact::TableLaw>(curve, false, h)),
          separation};
}

tapping::ShootingOptions tight() {
  tapping::ShootingOptions so;
  so.tolerance = 1e-13;
  so.simulation.relative_tolerance = 1e-12;
  so.simulation.absolute_tolerance = 1e-13;
  so.time_budget_seconds = 20;
  return so;
}

/// The orbit the tip settles on from the free oscillation (1500 periods, then shooting).
tapping::PeriodicOrbit orbit_of(const tapping::TappingModel& m) {
  const auto so = tight();
  tapping::SimulationOptions quick;
  const auto settled = tapping::simulate(m, 0.0, tapping::free_response_state(m), 1500 * m.period(), quick);
  auto orbit = tapping::try_shoot(m, settled.state, 1, so);
  if (!orbit) throw std::runtime_error("no periodic orbit");
  return *orbit;
}

tapping::OrbitMetrics metrics(const tapping::TappingModel& m, const tapping::PeriodicOrbit& o) {
  return tapping::analyse_orbit(m, o, tight().simulation);
}

/// ∫_lo^hi (H_a − H_b) dd of a law by 5-point Gauss–Legendre on every 0.1 nm knot interval of the neck curve
/// (the PCHIP interpolant is a cubic on each: exact), split at lo — independent of TableLaw::hysteresis_area.
double area_by_quadrature(const impact::ForceLaw& law, double lo, double hi) {
  using Rule = boost::math::quadrature::gauss<double, 5>;
  double sum = 0.0;
  double a = lo;
  while (a < hi) {
    double b = std::min(hi, -2.0 + 0.1 * (std::floor((a + 2.0) / 0.1 + 1e-9) + 1.0));
    if (b <= a) b = std::min(hi, a + 0.1);
    sum += Rule::integrate([&](double d) { return law.approach(d) - law.departure(d); }, a, b);
    a = b;
  }
  return sum;
}

}  // namespace

TEST(ContactHysteresis, TheTableLawKnowsItsContactAndReleaseGaps) {
  const auto contact = impact::make_law<impact::TableLaw>(afmkit_test::neck_curve());
  const auto velocity = impact::make_law<impact::TableLaw>(afmkit_test::neck_curve(), false, Hysteresis::velocity);
  EXPECT_TRUE(contact.contact_aware());  // the default of a table law
  EXPECT_FALSE(velocity.contact_aware());
  EXPECT_TRUE(std::isnan(velocity.release_gap()));
  // contact: the tabulated distance of the deepest approach force
  const auto curve = afmkit_test::neck_curve();
  std::size_t deepest = 0;
  for (std::size_t i = 0; i < curve.approach_force.size(); ++i)
    if (curve.approach_force[i] < curve.approach_force[deepest]) deepest = i;
  EXPECT_EQ(contact.contact_gap(), curve.approach_gap[deepest]);
  // release: where the neck ends (at 14 nm; its 4th-power tail falls below 1e-9 of the largest force one sample
  // earlier); above it the interpolated branches agree to that tolerance, below it they do not
  const double release = contact.release_gap();
  EXPECT_GE(release, afmkit_test::kPullOff - 0.1 - 1e-9);
  EXPECT_LE(release, afmkit_test::kPullOff + 0.1 + 1e-9);
  const double tolerance = 1e-9 * std::abs(curve.approach_force.front());  // the largest force (deepest point)
  for (double d = release; d < 40.5; d += 0.013)
    EXPECT_LE(std::abs(contact.approach(d) - contact.departure(d)), tolerance) << d;
  EXPECT_GT(std::abs(contact.approach(release - 0.2) - contact.departure(release - 0.2)), tolerance);
  for (double g : {contact.contact_gap(), contact.release_gap()})
    EXPECT_NE(std::find(contact.switching_gaps().begin(), contact.switching_gaps().end(), g),
              contact.switching_gaps().end());
  // the seed's laws keep the velocity-sign switching
  EXPECT_FALSE(impact::ForceLaw(impact::DmtLaw(1.0, 0.8, 10.0, 6.4e-20, 1e-19, 0.165)).contact_aware());
  EXPECT_FALSE(impact::ForceLaw(impact::PiecewiseLinearLaw(10.0, 8.0, 1.0, 2.0)).contact_aware());
}

TEST(ContactHysteresis, ModesCarryTheMemoryOfContact) {
  const auto m = model(kSoft, afmkit_test::neck_curve(), Hysteresis::contact, 25.0);
  const tapping::TappingSystem sys(m);
  ASSERT_TRUE(sys.contact_aware());
  // between the contact gap and the release gap (gap 5 nm), moving up: the state's memory decides
  tapping::TipState up{5.0 - 25.0, 1.0, false};
  const auto free_mode = sys.initial_mode(0.0, up);
  EXPECT_FALSE(free_mode.contact);
  EXPECT_EQ(free_mode.branch, tapping::ContactBranch::approach);  // free: H_a whatever the velocity
  up.contact = true;
  const auto contact_mode = sys.initial_mode(0.0, up);
  EXPECT_TRUE(contact_mode.contact);
  EXPECT_EQ(contact_mode.branch, tapping::ContactBranch::departure);
  // below the contact gap: in contact whatever the flag; above the release gap: free
  tapping::TipState deep{-0.5 - 25.0, 1.0, false};
  EXPECT_TRUE(sys.initial_mode(0.0, deep).contact);
  tapping::TipState high{20.0 - 25.0, 1.0, true};
  EXPECT_FALSE(sys.initial_mode(0.0, high).contact);
  // a free mode has no velocity guard: it never switches to the retract branch at a turning point
  std::array<tapping::Guard, 3> guards{};
  const int n = sys.guards(free_mode, guards);
  for (int i = 0; i < n; ++i) EXPECT_NE(guards[i].kind, tapping::GuardKind::velocity);
}

// (a) The outside report: the tip 25 nm above the surface, free amplitude 20 nm, never reaches the contact gap
// but crosses the neck range (5–14 nm) twice per cycle; at 40 nm it stays above the neck, where a measured
// curve still has a drag / baseline difference between its branches. Velocity-sign switching makes every branch
// difference a friction at every turning point; the contact-aware law dissipates nothing: the orbit is the
// conservative (approach-only) law's.
TEST(ContactHysteresis, AnOrbitThatNeverTouchesDissipatesNothingThroughTheLaw) {
  struct Case {
    double drag;  // nN
    double separation;
  };
  for (const Case c : {Case{0.0, 25.0}, Case{0.02, 25.0}, Case{0.02, 40.0}}) {
    SCOPED_TRACE(c.separation);
    const auto curve = afmkit_test::neck_curve(c.drag, 70.0);
    const auto aware = model(kSoft, curve, Hysteresis::contact, c.separation);
    const auto seed = model(kSoft, curve, Hysteresis::velocity, c.separation);
    const auto conservative = model(kSoft, afmkit_test::approach_only_curve(70.0), Hysteresis::velocity, c.separation);
    const auto oa = orbit_of(aware), os = orbit_of(seed), oc = orbit_of(conservative);
    const auto ma = metrics(aware, oa), ms = metrics(seed, os), mc = metrics(conservative, oc);
    const double a0 = kSoft.free_amplitude;
    std::printf("drag %.2f nN, separation %g nm: A/A0 velocity-sign %.4f (law work %.4g aJ/cycle), contact-aware "
                "%.6f (law work %.3g aJ), conservative %.6f; min gap %.3f nm\n",
                c.drag, c.separation, ms.amplitude / a0, ms.contact_dissipation * kSoft.spring_constant,
                ma.amplitude / a0, ma.contact_dissipation * kSoft.spring_constant, mc.amplitude / a0, ma.min_gap);
    // the orbit never reaches the contact gap but visits gaps where the branches differ (else this proves nothing)
    ASSERT_GT(ma.min_gap, aware.law.contact_gap() + 1.0);
    ASSERT_LT(ma.min_gap, c.drag > 0 ? 70.0 : afmkit_test::kPullOff - 1.0);
    // no work by the law over the period, to rounding (relative to the energy the medium dissipates per cycle)
    EXPECT_LE(std::abs(ma.contact_dissipation), 1e-10 * ma.viscous_dissipation);
    EXPECT_NEAR(ma.amplitude, mc.amplitude, 1e-8 * a0);
    EXPECT_NEAR(ma.phase, mc.phase, 1e-8);
    EXPECT_NEAR(ma.offset, mc.offset, 1e-8 * a0);
    // the seed's semantics dissipates (the defect this fixes)
    EXPECT_GT(ms.contact_dissipation, 0.02 * ms.viscous_dissipation);
    EXPECT_LT(ms.amplitude, 0.97 * ma.amplitude);
  }
}

/// The highest gap of an orbit (dense sampling; its error ~ (ωΔt)²B/2 ≈ 1e-7 nm is far below what matters here).
double max_gap(const tapping::TappingModel& m, const tapping::PeriodicOrbit& o) {
  std::vector<double> times;
  for (int i = 0; i <= 20000; ++i) times.push_back(m.period() * i / 20000.0);
  tapping::SampleRecorder rec(times);
  tapping::simulate(m, 0.0, o.initial, m.period(), tight().simulation, &rec);
  double top = -1e300;
  for (const auto& s : rec.states()) top = std::max(top, s.position + m.separation);
  return top;
}

// (b) An orbit dissipates the area between the branches over the part of the curve it visits in contact: a tapping
// orbit from its minimum gap up to the release gap (H_a = H_b above); an orbit that touched once and stays attached
// to the neck (never rising above the release gap) over [min gap, max gap]. For a period-1 tapping orbit that is
// also what the velocity-sign law does.
TEST(ContactHysteresis, AnOrbitInContactDissipatesTheAreaBetweenTheBranchesVisited) {
  struct Case {
    const tapping::PhysicalCantilever* pc;
    double separation;
  };
  for (const Case c : {Case{&kTap, 13.0}, Case{&kStiff, 6.0}}) {
    const double separation = c.separation;
    SCOPED_TRACE(separation);
    const auto aware = model(*c.pc, afmkit_test::neck_curve(), Hysteresis::contact, separation);
    const auto oa = orbit_of(aware);
    const auto ma = metrics(aware, oa);
    const double top = max_gap(aware, oa);
    const bool tapping_orbit = ma.min_gap < aware.law.contact_gap();
    ASSERT_TRUE(tapping_orbit ? top > aware.law.release_gap() : oa.initial.contact);
    const double area = area_by_quadrature(aware.law, ma.min_gap, std::min(top, aware.law.release_gap()));
    std::printf("separation %g nm (%s): gap %.4f..%.4f nm, law work %.12g, quadrature of H_a - H_b %.12g "
                "(normalised)\n",
                separation, tapping_orbit ? "tapping" : "attached to the neck", ma.min_gap, top,
                ma.contact_dissipation, area);
    EXPECT_GT(area, 0.0);
    EXPECT_NEAR(ma.contact_dissipation, area, 1e-7 * area);
    EXPECT_NEAR(ma.drive_work, ma.viscous_dissipation + ma.contact_dissipation, 1e-8 * ma.drive_work);
    if (tapping_orbit) {  // a single load/unload per cycle: the same orbit as the velocity-sign law
      const auto seed = model(*c.pc, afmkit_test::neck_curve(), Hysteresis::velocity, separation);
      const auto ms = metrics(seed, tapping::shoot(seed, oa.initial, 1, tight()));
      EXPECT_NEAR(ma.amplitude, ms.amplitude, 1e-8 * c.pc->free_amplitude);
      EXPECT_NEAR(ma.phase, ms.phase, 1e-8);
    }
  }
}

// The mode switches are events: one contact entry at the contact gap (falling) and one release at the release gap
// (rising) per period of a touching orbit; the monodromy (variational equations + saltation) matches finite
// differences of the stroboscopic map across them.
TEST(ContactHysteresis, ContactEntryAndReleaseAreEventsAndTheMonodromyStaysExact) {
  const auto m = model(kTap, afmkit_test::neck_curve(), Hysteresis::contact, 13.0);
  const auto o = orbit_of(m);
  tapping::EventRecorder events;
  tapping::simulate(m, 0.0, o.initial, m.period(), tight().simulation, &events);
  int entries = 0, releases = 0;
  for (const auto& e : events.events()) {
    const double gap = e.state.position + m.separation;
    if (!e.before.contact && e.after.contact) {
      ++entries;
      EXPECT_NEAR(gap, m.law.contact_gap(), 1e-9);
      EXPECT_EQ(e.guard.direction, tapping::CrossingDirection::falling);
    }
    if (e.before.contact && !e.after.contact) {
      ++releases;
      EXPECT_NEAR(gap, m.law.release_gap(), 1e-9);
      EXPECT_EQ(e.guard.direction, tapping::CrossingDirection::rising);
    }
  }
  EXPECT_EQ(entries, 1);
  EXPECT_EQ(releases, 1);
  // monodromy against central differences of the map (the memory is the orbit's: free at t = 0 here or not)
  const auto so = tight();
  const double h[2] = {1e-5, 1e-5};
  for (int j = 0; j < 2; ++j) {
    tapping::TipState plus = o.initial, minus = o.initial;
    (j == 0 ? plus.position : plus.velocity) += h[j];
    (j == 0 ? minus.position : minus.velocity) -= h[j];
    const auto fp = tapping::simulate(m, 0.0, plus, m.period(), so.simulation).state;
    const auto fm = tapping::simulate(m, 0.0, minus, m.period(), so.simulation).state;
    const double dx = (fp.position - fm.position) / (2 * h[j]), dv = (fp.velocity - fm.velocity) / (2 * h[j]);
    const double scale = std::abs(o.monodromy(0, j)) + std::abs(o.monodromy(1, j)) + 1e-3;
    // (the PCHIP law is only C¹ at its knots: central differences are first-order accurate there)
    EXPECT_NEAR(o.monodromy(0, j), dx, 2e-3 * scale) << "column " << j;
    EXPECT_NEAR(o.monodromy(1, j), dv, 2e-3 * scale) << "column " << j;
  }
  // and to rounding against the velocity-sign law on the same (tapping) orbit, whose saltation matrices the seed
  // tests check: the contact entry and the release add no jump of the vector field (H_a = H_b at d_r)
  const auto seed = model(kTap, afmkit_test::neck_curve(), Hysteresis::velocity, 13.0);
  const auto os = tapping::shoot(seed, o.initial, 1, so);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(o.monodromy(i, j), os.monodromy(i, j), 1e-6 * o.monodromy.norm());
}

// (e) A long time simulation from a perturbed start settles onto the orbit found by shooting (same state at the
// same drive phase: amplitude and phase), touching or not.
TEST(ContactHysteresis, TimeSimulationSettlesOntoTheShotOrbit) {
  struct Case {
    const tapping::PhysicalCantilever* pc;
    double separation;
    int periods;
  };
  for (const Case c : {Case{&kSoft, 25.0, 1500}, Case{&kTap, 13.0, 3000}, Case{&kStiff, 6.0, 3000}}) {
    SCOPED_TRACE(c.separation);
    const auto m = model(*c.pc, afmkit_test::neck_curve(), Hysteresis::contact, c.separation);
    const auto o = orbit_of(m);
    tapping::TipState start = o.initial;
    start.position += 0.05 * c.pc->free_amplitude;  // off the orbit, memory not given
    start.contact = false;
    tapping::SimulationOptions so = tight().simulation;
    so.relative_tolerance = 1e-11;
    const auto r = tapping::simulate(m, 0.0, start, c.periods * m.period(), so);
    const double a0 = c.pc->free_amplitude;
    EXPECT_NEAR(r.state.position, o.initial.position, 1e-6 * a0);
    EXPECT_NEAR(r.state.velocity, o.initial.velocity, 1e-6 * a0);
    EXPECT_EQ(r.state.contact, o.initial.contact);
  }
}

// A measured curve's drag / baseline difference up to the table's end puts the release gap there; a release
// tolerance above that difference puts it back at the neck's end, so a tip that touched is released at pull-off.
TEST(ContactHysteresis, AReleaseToleranceIgnoresADragDifferenceAboveThePullOff) {
  const auto curve = afmkit_test::neck_curve(0.02, 70.0);
  const impact::TableLaw strict(curve);
  EXPECT_NEAR(strict.release_gap(), 70.0, 1e-9);
  const impact::TableLaw tolerant(curve, false, Hysteresis::contact, 0.03);
  // independent: the largest sample where the neck (3 nN (1 − u)⁴) plus the drag still exceeds 0.03 nN, within a
  // sample spacing (the interpolant between samples)
  double last = -2.0;
  for (std::size_t i = 0; i < curve.retract_gap.size(); ++i) {
    const double d = curve.retract_gap[i];
    if (afmkit_test::neck_force(d) + 0.02 > 0.03 && d > 0.5) last = d;
  }
  EXPECT_GE(tolerant.release_gap(), last - 1e-9);
  EXPECT_LE(tolerant.release_gap(), last + 0.2 + 1e-9);
  EXPECT_THROW(impact::TableLaw(curve, false, Hysteresis::contact, -1.0), InvalidParameter);
  // the soft cantilever 25 nm away, started in contact (gap −0.5 nm, at rest): without the tolerance the tip stays
  // "in contact" (never above 70 nm) and the drag dissipates at every turn; with it, it is released at pull-off and
  // settles on the free orbit
  auto settled = [&](double tolerance) {
    const tapping::TappingModel m{kSoft.cantilever(), kSoft.drive(),
                                  kSoft.normalised_law(impact::make_law<impact::TableLaw>(curve, false,
                                                                                         Hysteresis::contact, tolerance)),
                                  25.0};
    const auto end = tapping::simulate(m, 0.0, {-25.5, 0.0, true}, 1500 * m.period(), {});
    const auto o = tapping::shoot(m, end.state, 1, tight());
    return std::pair{o, metrics(m, o)};
  };
  const auto [attached, ma] = settled(0.0);
  const auto [released, mr] = settled(0.03);
  EXPECT_TRUE(attached.initial.contact);
  EXPECT_GT(ma.contact_dissipation, 0.02 * ma.viscous_dissipation);
  EXPECT_FALSE(released.initial.contact);
  EXPECT_LE(std::abs(mr.contact_dissipation), 1e-10 * mr.viscous_dissipation);
  EXPECT_GT(mr.amplitude, 0.999 * kSoft.free_amplitude);
}
