// Cancellation (core/cancellation.hpp) of the tapping computations that run point after point: the instrument
// sweep, the grid of orbit searches, the orbit search itself and the arclength continuation stop within one point
// of the request.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <string>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/core/error.hpp"
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

// issue 24 §2 (library level): what is refused inside a sweep, a continuation or a grid was computed — as the
// predictor's NaN separation of a stuck tip was — and crosses the library's entry points as a NumericalFailure
// naming the computation, never as the user's InvalidParameter. A hook that refuses a "separation" on its third
// call stands in for a computed value refused deep inside (the hooks run where the computation runs).
TEST(ComputedBoundary, WhatIsRefusedInsideASweepIsANumericalFailure) {
  auto refusing = [] {
    auto calls = std::make_shared<int>(0);
    return Cancellation([calls]() -> bool {
      if (++*calls == 3) throw InvalidParameter("separation", "separation = nan is out of range");
      return false;
    });
  };
  auto expect_numerical = [](auto&& run, const std::string& what) {
    try {
      run();
      ADD_FAILURE() << what << ": the refusal did not reach the caller";
    } catch (const NumericalFailure& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("not an error in the input"), std::string::npos) << e.what();
    } catch (const InvalidParameter& e) {
      ADD_FAILURE() << what << ": reported as the user's error: " << e.what();
    }
  };
  SweepOptions s;
  s.parallel = false;
  s.cancellation = refusing();
  expect_numerical([&] { sweep_instrument(repulsive_model(), 8.0, 11.0, 20, s); }, "instrument sweep");
  ContinuationOptions c;
  c.cancellation = refusing();
  expect_numerical([&] { sweep_continuation(repulsive_model(), 8.8, 10.4, c); }, "");
  OrbitSearchOptions o;
  o.parallel = false;
  o.cancellation = refusing();
  expect_numerical([&] { sweep_grid(repulsive_model(), {9.0, 10.0}, o); }, "");
  // the input itself is still the user's error
  EXPECT_THROW(sweep_instrument(repulsive_model(), 11.0, 8.0, 20, SweepOptions{}), InvalidParameter);
  EXPECT_THROW(sweep_continuation(repulsive_model(), 8.8, std::nan(""), ContinuationOptions{}), InvalidParameter);
  EXPECT_THROW(sweep_grid(repulsive_model(), {9.0, std::nan("")}, OrbitSearchOptions{}), InvalidParameter);
}
