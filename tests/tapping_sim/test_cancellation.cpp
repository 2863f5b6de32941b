// Cancellation (core/cancellation.hpp) of the tapping computations that run point after point: the instrument
// sweep, the grid of orbit searches, the orbit search itself and the arclength continuation stop within one point
// of the request.
#include <gtest/gtest.h>

#include <atomic>

#include "afmkit/core/cancellation.hpp"
#include "../counting_stop.hpp"
#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/transient.hpp"
#include "fixtures.hpp"

using namespace afmkit;
using afmkit_test::CountingStop;
using namespace afmkit::tapping;
using namespace afmkit::tapping::testing;

TEST(Cancellation, AnInstrumentSweepStopsAtThePointOfTheRequest) {
  SweepOptions o;
  CountingStop stop(5);
  o.cancellation = stop.cancellation();
  EXPECT_THROW(sweep_instrument(repulsive_model(), 8.0, 11.0, 200, o), Cancelled);
  EXPECT_EQ(stop.calls.load(), 5);  // serial: the fifth point's check threw, no point after it was computed
}

TEST(Cancellation, AGridOfOrbitSearchesAndAContinuationStop) {
  OrbitSearchOptions o;
  CountingStop grid(2);
  o.cancellation = grid.cancellation();
  EXPECT_THROW(sweep_grid(repulsive_model(), {9.0, 9.5, 10.0, 10.5, 11.0, 11.5}, o), Cancelled);
  EXPECT_LE(grid.calls.load(), 2 + 2);

  ContinuationOptions c;
  CountingStop cont(3);
  c.cancellation = cont.cancellation();
  EXPECT_THROW(sweep_continuation(repulsive_model(), 8.8, 10.4, c), Cancelled);
}

// issue 24 §3: a long transient (max_periods of 1e8 at a quality factor of 1e9) ran for minutes without a check;
// it now checks once per chunk of chunk_periods periods, and find_orbits / the sweeps hand it their cancellation.
TEST(Cancellation, ALongTransientStopsWithinAChunk) {
  const TappingModel model = make_model(10, 8, 0, 0, 10.0, 1.0, 1e6);  // Q = 1e6: settles in ~1e6 periods
  TransientOptions t;
  t.max_periods = 2400;  // (without the check the transient ends, not settled, after these 100 chunks)
  CountingStop stop(3);
  t.cancellation = stop.cancellation();
  EXPECT_THROW(settle(model, {0.0, 0.0}, t), Cancelled);
  EXPECT_EQ(stop.calls.load(), 3);  // one check per chunk: stopped at the third
}

TEST(Cancellation, TheOrbitSearchPassesItsCancellationToItsTransients) {
  const TappingModel model = make_model(10, 8, 0, 0, 10.0, 1.0, 1e6);
  OrbitSearchOptions o;
  o.transient.max_periods = 4800;
  o.from_grid = false;
  o.from_continuation = false;
  o.parallel = false;
  CountingStop stop(12);  // the search's own checks: one per candidate (HB solutions and 2 transients: fewer)
  o.cancellation = stop.cancellation();
  EXPECT_THROW(find_orbits(model, o), Cancelled);
  EXPECT_EQ(stop.calls.load(), 12);
}
