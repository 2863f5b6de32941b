// Cancellation (core/cancellation.hpp) of the long control computations: a stop request is honoured within one
// point of the chart, margin map and tuning loops (the hook is consulted once per point; a request makes the next
// check on every thread throw), and an empty Cancellation changes nothing.
#include <gtest/gtest.h>

#include <atomic>

#include "afmkit/control/stability_chart.hpp"
#include "afmkit/control/tuning.hpp"
#include "afmkit/core/cancellation.hpp"
#include "../counting_stop.hpp"

using namespace afmkit;
using afmkit_test::CountingStop;
using namespace afmkit::control;

namespace {

LoopFamily family() {
  return LoopFamily::from_loop(LoopSpec(OscillatorBank::single(1.0, 0.5, 0.0, 20.0), PlantKind::Static, 20.0, 0.3));
}

}  // namespace

TEST(Cancellation, EmptyNeverStopsAndARequestStopsEveryCheck) {
  const Cancellation none;
  EXPECT_NO_THROW(none.check());
  none.request();  // no effect without state
  EXPECT_FALSE(none.requested());
  const Cancellation c([] { return false; });
  EXPECT_NO_THROW(c.check());
  const Cancellation copy = c;  // copies share the request
  copy.request();
  EXPECT_TRUE(c.requested());
  EXPECT_THROW(c.check(), Cancelled);
}

TEST(Cancellation, AChartStopsWithinAPointOfTheRequest) {
  ChartSpec s;
  s.family = family();
  s.x_min = -0.5, s.x_max = 2.0, s.y_min = -2.0, s.y_max = 1.5;
  s.x_points = s.y_points = 60;  // 3600 points
  s.threads = 2;
  CountingStop stop(100);
  s.cancellation = stop.cancellation();
  EXPECT_THROW(stability_chart(s), Cancelled);
  // after the request every check throws before consulting the hook again: at most one call per thread beyond it
  EXPECT_LE(stop.calls.load(), 100 + 2);
  // unchanged without a request (the empty default)
  s.cancellation = Cancellation{};
  s.x_points = s.y_points = 8;
  const StabilityChart c = stability_chart(s);
  EXPECT_EQ(c.abscissa.size(), 64u);
}

TEST(Cancellation, AMarginMapAndATuningStop) {
  CountingStop map_stop(10);
  EXPECT_THROW(delay_margin_map(family(), -0.5, 2.0, 40, -2.0, 1.5, 40, 2, {}, map_stop.cancellation()), Cancelled);
  EXPECT_LE(map_stop.calls.load(), 10 + 2);

  RobustTuningSpec t;
  t.family = LoopFamily::from_loop(LoopSpec(InfiniteBank(1.0, 0.1, -0.1, 20.0), PlantKind::Static, 20.0, 0.1));
  t.delay_max = 0.2;
  t.coarse_points = 12;
  t.threads = 2;
  CountingStop tune_stop(20);
  t.cancellation = tune_stop.cancellation();
  EXPECT_THROW(robust_tuning(t), Cancelled);
  EXPECT_LE(tune_stop.calls.load(), 20 + 2);
}
