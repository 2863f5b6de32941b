// simulate(const TappingSystem&) on a system whose separation was moved in place (TappingSystem::set_separation, the
// time-domain imaging engine's per-cycle step) gives bit for bit what simulate(TappingModel) gives at that separation,
// for the closed-form flow and the adaptive integrator alike.
#include <gtest/gtest.h>

#include "afmkit/impact/force_law.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/simulation.hpp"
#include "afmkit/tapping/system.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::tapping {
namespace {

void sysmove_expect_same(const TappingModel& base, const SimulationOptions& options) {
  TappingSystem system(base);
  TipState state = free_response_state(base);  // swinging with A0 = 10 nm: every separation below is touched
  for (const double l : {9.0, 6.5, 7.25, 8.0}) {  // the separation moves between runs, the state carries over
    system.set_separation(l);
    const SimulationResult a = simulate(system, 0.0, state, 3.0 * base.period(), options);
    const SimulationResult b = simulate(base.with_separation(l), 0.0, state, 3.0 * base.period(), options);
    EXPECT_EQ(a.state.position, b.state.position) << "l = " << l;
    EXPECT_EQ(a.state.velocity, b.state.velocity) << "l = " << l;
    EXPECT_EQ(a.stats.events, b.stats.events) << "l = " << l;
    EXPECT_GT(a.stats.impacts, 0) << "l = " << l;  // the moved sample is touched
    state = a.state;
  }
}

TEST(SystemSeparation, AMovedSeparationSimulatesAsTheModelAtThatSeparation) {
  const PhysicalCantilever pc(40.0, 300.0, 100.0, 10.0, 1.0);
  {
    SCOPED_TRACE("closed form (piecewise-linear law)");
    const TappingModel m(pc.cantilever(), pc.drive(),
                         pc.normalised_law(impact::ForceLaw(impact::PiecewiseLinearLaw::linear_hysteresis(50.0, 40.0))),
                         20.0);
    sysmove_expect_same(m, {});
  }
  {
    SCOPED_TRACE("adaptive (DMT + vdW)");
    const TappingModel m(pc.cantilever(), pc.drive(),
                         pc.normalised_law(impact::ForceLaw(impact::DmtLaw(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165))),
                         20.0);
    sysmove_expect_same(m, {});
  }
}

}  // namespace
}  // namespace afmkit::tapping
