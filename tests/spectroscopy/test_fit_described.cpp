// The fit's solver settings are declared once (spectroscopy::FitOptions::describe) and their declared ranges are the
// ones FitOptions::validate checks (tests/described_probe.hpp).
#include <gtest/gtest.h>

#include "../described_probe.hpp"
#include "afmkit/spectroscopy/fit.hpp"

namespace {

TEST(DescribedFitOptions, TheSolverSettingsCheckTheirDeclaredRanges) {
  afmkit_test::expect_described_ranges_checked(afmkit::spectroscopy::FitOptions{},
                                               [](const afmkit::spectroscopy::FitOptions& o) { o.validate(); });
}

}  // namespace
