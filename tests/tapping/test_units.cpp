#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/units.hpp"

using namespace afmkit::tapping;

// Independent check in SI units: m ẍ + c ẋ + k x = F0 cos(ωt) has steady amplitude F0 / sqrt((k − mω²)² + (cω)²).
TEST(Units, PhysicalDriveGivesTheStatedFreeAmplitude) {
  for (double ratio : {0.9, 0.99, 1.0, 1.01, 1.2}) {
    PhysicalCantilever pc(40.0, 300.0, 400.0, 20.0, ratio);
    const double w0 = 2 * std::numbers::pi * 300e3, k = 40.0, m = k / (w0 * w0), c = m * w0 / 400.0;
    const double w = ratio * w0;
    // normalised drive Γ [nm·ω_n²] per unit mass -> force F0 = m Γ ω_n² (in nN when lengths are nm: k·Γ)
    const double gamma = pc.drive().amplitude;
    const double f0_newton = m * gamma * 1e-9 * w0 * w0;
    const double amp_m = f0_newton / std::hypot(k - m * w * w, c * w);
    EXPECT_NEAR(amp_m * 1e9, 20.0, 1e-9);
    EXPECT_DOUBLE_EQ(pc.drive().frequency, ratio);
  }
}

TEST(Units, ScalesConvertForcesEnergiesAndTime) {
  PhysicalCantilever pc(40.0, 300.0, 100.0, 20.0, 1.0);
  const auto s = pc.scales();
  EXPECT_DOUBLE_EQ(s.force, 40.0);                                   // 1 nm of h <-> k·1 nm = 40 nN
  EXPECT_DOUBLE_EQ(pc.normalised_force(40.0), 1.0);                  // 40 nN -> 1 nm·ω_n²
  EXPECT_DOUBLE_EQ(pc.normalised_stiffness(400.0), 10.0);            // 400 N/m -> K = 10 ω_n²
  EXPECT_NEAR(s.energy * 1e-18, 40.0 * 1e-18, 1e-30);                // k·nm² in J
  EXPECT_NEAR(s.time, 1.0 / (2 * std::numbers::pi * 300e3), 1e-20);  // one radian of the resonance
}

TEST(Units, BadPhysicalInputIsNamed) {
  try {
    PhysicalCantilever(-1.0, 300.0, 100.0, 20.0, 1.0);
    FAIL();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "spring_constant");
  }
  EXPECT_THROW(PhysicalCantilever(40.0, 300.0, std::nan(""), 20.0, 1.0), afmkit::InvalidParameter);
  EXPECT_THROW(Cantilever(1.0, 0.0), afmkit::InvalidParameter);
  EXPECT_THROW(Drive(0.2, -1.0), afmkit::InvalidParameter);
}

// The C++ API takes the cantilever's settings in the ranges the command line and Python take (docs/bad-input.md:
// k in (0, 1e6] N/m, f0 in (0, 1e7] kHz, Q in (0, 1e9], A_free in (0, 1e6] nm): a value above the upper bound is
// refused naming its key and the range in the unit it was given in; the bounds themselves are accepted.
TEST(Units, PhysicalCantileverTakesTheCommandLinesRanges) {
  struct Case {
    const char* key;
    double k, f0, q, a;
    const char* range;
  };
  for (const Case& c : {Case{"spring_constant", 1.5e6, 300.0, 100.0, 20.0, "<= 1e+06 N/m"},
                        Case{"resonance_frequency", 40.0, 2e7, 100.0, 20.0, "<= 1e+07 kHz"},
                        Case{"quality_factor", 40.0, 300.0, 3e9, 20.0, "<= 1e+09"},
                        Case{"free_amplitude", 40.0, 300.0, 100.0, 1.5e6, "<= 1e+06 nm"}}) {
    try {
      PhysicalCantilever(c.k, c.f0, c.q, c.a, 1.0);
      ADD_FAILURE() << c.key << " above its upper bound was accepted";
    } catch (const afmkit::InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), c.key);
      EXPECT_NE(std::string(e.what()).find(c.range), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(PhysicalCantilever(1e6, 1e7, 1e9, 1e6, 1.0));  // every upper bound itself
  EXPECT_THROW(PhysicalCantilever(40.0, 300.0, 100.0, 20.0, 0.0), afmkit::InvalidParameter);  // ratio: > 0
}
