// Frequency response: grids, phase unwrapping, plant / controller / loop responses vs analytic forms.
#include <gtest/gtest.h>

#include <numbers>

#include "afmkit/control/frequency_response.hpp"
#include "afmkit/core/error.hpp"

using namespace afmkit::control;
using cplx = std::complex<double>;

TEST(FrequencyResponse, Grids) {
  const auto lin = frequency_grid(0.0, 2.0, 5, false);
  EXPECT_EQ(lin, (std::vector<double>{0.0, 0.5, 1.0, 1.5, 2.0}));
  const auto lg = frequency_grid(0.01, 100.0, 5, true);
  EXPECT_DOUBLE_EQ(lg.front(), 0.01);
  EXPECT_DOUBLE_EQ(lg.back(), 100.0);
  for (int i = 1; i < 5; ++i) EXPECT_NEAR(lg[i] / lg[i - 1], 10.0, 1e-12);
  EXPECT_THROW(frequency_grid(0.0, 1.0, 10, true), afmkit::InvalidParameter);
  EXPECT_THROW(frequency_grid(2.0, 1.0, 10, false), afmkit::InvalidParameter);
  EXPECT_THROW(frequency_grid(0.0, 1.0, 1, false), afmkit::InvalidParameter);
}

TEST(FrequencyResponse, PureDelayPhaseIsUnwrappedToMinusOmegaTau) {
  const double tau = 1.7;
  const auto w = frequency_grid(0.0, 60.0, 3001, false);  // steps of 0.02 rad/s: phase steps 0.034 rad
  const auto r = frequency_response([&](cplx s) { return std::exp(-s * tau); }, w);
  for (std::size_t i = 0; i < w.size(); ++i) {
    EXPECT_NEAR(r.phase[i], -w[i] * tau, 1e-9) << w[i];
    EXPECT_NEAR(r.magnitude[i], 1.0, 1e-15);
  }
}

TEST(FrequencyResponse, PlantResponsesMatchClosedForms) {
  const auto bank = OscillatorBank::with_couplings(1.0, 4, 0.1, -0.1, 20.0);
  const double gamma = 20.0, tau = 0.3;
  const LoopSpec first(bank, PlantKind::FirstOrder, gamma, tau), stat(bank, PlantKind::Static, gamma, tau);
  const auto w = frequency_grid(0.01, 30.0, 400, true);
  const auto rf = frequency_response(first, LoopSystem::Plant, w);
  const auto rs = frequency_response(stat, LoopSystem::Plant, w);
  for (std::size_t i = 0; i < w.size(); ++i) {
    EXPECT_NEAR(rf.magnitude[i], 1.0 / std::hypot(w[i], gamma), 1e-15);
    EXPECT_NEAR(rf.phase[i], -std::atan(w[i] / gamma) - w[i] * tau, 1e-12);
    EXPECT_NEAR(rs.magnitude[i], 1.0 / gamma, 1e-16);
    EXPECT_NEAR(rs.phase[i], -w[i] * tau, 1e-12);
  }
}

TEST(FrequencyResponse, PoleOnTheGridAndConsistencyOfRepresentations) {
  const auto bank = OscillatorBank::with_couplings(1.0, 3, 0.1, -0.1, 20.0);
  const auto w = frequency_grid(0.0, 2.0, 21, false);  // contains ω = Ω = 1 exactly
  const auto rc = frequency_response(Controller(bank), w);
  EXPECT_TRUE(std::isinf(rc.magnitude[10]));
  EXPECT_TRUE(std::isnan(rc.phase[10]));
  for (std::size_t i = 1; i < w.size(); ++i) {
    if (i == 10 || i == 11) continue;
    EXPECT_LE(std::abs(rc.phase[i] - rc.phase[i - 1]), std::numbers::pi) << i;  // unwrapped
  }
  const auto w2 = frequency_grid(0.05, 5.0, 50, true);
  const auto a = frequency_response(ss(bank), w2), b = frequency_response(tf(bank), w2),
             c = frequency_response(Controller(bank), w2);
  for (std::size_t i = 0; i < w2.size(); ++i) {
    EXPECT_NEAR(a.magnitude[i], c.magnitude[i], 1e-12 * c.magnitude[i]);
    EXPECT_NEAR(b.magnitude[i], c.magnitude[i], 1e-12 * c.magnitude[i]);
    EXPECT_NEAR(a.phase[i], c.phase[i], 1e-12);
  }
  const LoopSpec loop(bank, PlantKind::FirstOrder, 20.0, 0.5);
  const auto cl = frequency_response(loop, LoopSystem::ClosedLoop, w2);
  const auto sens = frequency_response(loop, LoopSystem::Sensitivity, w2);
  const auto lp = frequency_response(loop, LoopSystem::Loop, w2);
  for (std::size_t i = 0; i < w2.size(); ++i) {
    const cplx s(0.0, w2[i]);
    EXPECT_LT(std::abs(cl.response[i] - 20.0 / (s + 20.0) / (1.0 + lp.response[i])), 1e-12);
    EXPECT_LT(std::abs(sens.response[i] - 1.0 / (1.0 + lp.response[i])), 1e-12);
  }
}
