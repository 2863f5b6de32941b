// Cancellation (core/cancellation.hpp) of the tapping computations that run point after point: the instrument
// sweep, the grid of orbit searches, the orbit search itself and the arclength continuation stop within one point
// of the request.
#include <gtest/gtest.h>

#include <atomic>

#include "afmkit/core/cancellation.hpp"
#include "../counting_stop.hpp"
#include "afmkit/tapping/continuation.hpp"
#include "afmkit/tapping/sweep.hpp"
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
