// A tip held by the sample (issue 24 §2): an adhesion far above the drive traps the tip; the orbit search says so
// (tip_trapped) and its branch continuations fail as computations (NumericalFailure), never as a bad separation.
#include <gtest/gtest.h>

#include <cmath>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "fixtures.hpp"

using namespace afmkit::tapping;
using afmkit::InvalidParameter;
using afmkit::NumericalFailure;

namespace {
// law (26) with F_a = 5, F_b = 8 against a drive Γ = 0.2 (per unit mass): once touching, the drive cannot pull off
TappingModel sticky(double separation) { return afmkit::tapping::testing::make_model(10, 8, 5, 8, separation); }
}  // namespace

TEST(TrappedTip, EveryOrbitOfAStickyTipIsTrappedAndAFreeOrbitIsNot) {
  const OrbitSearchResult r = find_orbits(sticky(0.0));
  ASSERT_FALSE(r.orbits.empty());
  for (const FoundOrbit& f : r.orbits) {
    EXPECT_TRUE(tip_trapped(f.metrics)) << "amplitude " << f.metrics.amplitude;
    // independent of the flag: the tip does not move (at rest in the sticking band) and stays in or at contact
    // (the law's contact gap is 0: x + l <= 0 over the orbit, the highest gap at most min_gap + 2 B)
    EXPECT_LT(f.metrics.amplitude, 1e-9);
    EXPECT_LE(f.metrics.min_gap + 2.0 * f.metrics.amplitude, 1e-9);
    EXPECT_GT(f.metrics.duration, 0.0);
  }
  // far from the sample the tip oscillates freely: not trapped
  const OrbitSearchResult free = find_orbits(sticky(30.0));
  ASSERT_FALSE(free.orbits.empty());
  for (const FoundOrbit& f : free.orbits) EXPECT_FALSE(tip_trapped(f.metrics));
}

TEST(TrappedTip, ContinuingTheBranchOfAStuckTipIsANumericalFailureNeverABadSeparation) {
  // at rest in the sticking band every nearby rest state is an orbit too: the shooting Jacobian is singular and the
  // tangent is NaN; the continuation used to build a model at separation = NaN (InvalidParameter "separation")
  const OrbitSearchResult r = find_orbits(sticky(0.0));
  int tried = 0;
  for (const FoundOrbit& f : r.orbits) {
    if (f.orbit.period_multiple != 1) continue;
    ++tried;
    ContinuationOptions o;
    o.max_points = 20;
    try {
      const ContinuationResult c = continue_orbits(sticky(0.0), f.orbit, -1.0, 1.0, true, o);
      for (const SweepPoint& p : c.points) EXPECT_TRUE(std::isfinite(p.separation));
    } catch (const NumericalFailure&) {
      // a failure of the computation: fine
    } catch (const InvalidParameter& e) {
      ADD_FAILURE() << "an internal failure reported as bad input: " << e.what();
    }
  }
  EXPECT_GT(tried, 0);
}
