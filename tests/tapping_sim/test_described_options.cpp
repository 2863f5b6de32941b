// The tapping numerics declare each field once (describe(): key, help, unit, range) and check exactly the declared
// ranges, naming the key the command line and Python use (tests/described_probe.hpp).
#include <gtest/gtest.h>

#include "../described_probe.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/simulation.hpp"
#include "afmkit/tapping/transient.hpp"

namespace {

using afmkit_test::expect_described_ranges_checked;

TEST(DescribedTappingOptions, SimulationOptionsCheckTheirDeclaredRanges) {
  expect_described_ranges_checked(afmkit::tapping::SimulationOptions{},
                                  [](const afmkit::tapping::SimulationOptions& o) { o.validate(); });
}

TEST(DescribedTappingOptions, ShootingOptionsCheckTheirDeclaredRanges) {
  expect_described_ranges_checked(afmkit::tapping::ShootingOptions{},
                                  [](const afmkit::tapping::ShootingOptions& o) { o.validate(); });
}

TEST(DescribedTappingOptions, TransientOptionsCheckTheirDeclaredRanges) {
  expect_described_ranges_checked(afmkit::tapping::TransientOptions{},
                                  [](const afmkit::tapping::TransientOptions& o) { o.validate(); });
}

TEST(DescribedTappingOptions, TheShootingTimeBudgetIsThirtySeconds) {
  // one default for the library and the command line (the library had 5 s, `--time-budget` 30 s)
  EXPECT_EQ(afmkit::tapping::ShootingOptions{}.time_budget_seconds, 30.0);
}

}  // namespace
