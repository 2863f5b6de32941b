// Robust tuning: the objective against certified spectra at the grid points, optimum at least as good as the
// coarse grid, margins at the extremes of ρ larger than τ_max when the worst-case decay is positive.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/control/tuning.hpp"
#include "afmkit/core/error.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit;
using namespace afmkit::control;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kGamma;
using afmkit_test::fig5::kT;

RobustTuningSpec spec(bool infinite) {
  RobustTuningSpec s;
  s.family = infinite ? LoopFamily::from_loop(LoopSpec(InfiniteBank(kOmega, 0.1, -0.1, kGamma), PlantKind::Static, kGamma, 0.0))
                      : LoopFamily::from_loop(LoopSpec(OscillatorBank::with_couplings(kOmega, 4, 0.1, -0.1, kGamma),
                                                       PlantKind::Static, kGamma, 0.0));
  s.delay_max = 0.2 * kT;
  s.delay_points = 3;
  s.gain_ratio_min = 0.8;
  s.gain_ratio_max = 1.25;
  s.gain_points = 2;
  s.x_min = 0.02;
  s.x_max = 0.4;
  s.y_min = -0.22;
  s.y_max = 0.2;
  s.coarse_points = 4;
  s.max_evaluations = 25;
  s.threads = 2;
  return s;
}
}  // namespace

TEST(RobustTuning, ObjectiveEqualsCertifiedSpectraOnTheGrid) {
  for (bool infinite : {false, true}) {
    const RobustTuningSpec s = spec(infinite);
    for (auto [x, y] : {std::pair{0.1, -0.1}, std::pair{0.3, 0.1}}) {
      double wd = 0, wr = 0;
      const double j = worst_case_decay(s, x, y, &wd, &wr);
      double ref = INFINITY;
      for (double rho : {0.8, 1.25})
        for (double tau : {0.0, 0.1 * kT, 0.2 * kT})
          ref = std::min(ref, -rightmost_roots(s.family.at(x, y, tau, rho)).spectral_abscissa);
      EXPECT_NEAR(j, ref, 1e-8) << infinite << " " << x << " " << y;
      EXPECT_NEAR(-rightmost_roots(s.family.at(x, y, wd, wr)).spectral_abscissa, j, 1e-8);
    }
  }
}

TEST(RobustTuning, OptimumBeatsCoarseGridAndKeepsMargins) {
  const RobustTuningSpec s = spec(true);
  const RobustTuning r = robust_tuning(s);
  ASSERT_EQ(r.coarse_worst_decay.size(), 16u);
  const double coarse_best = *std::max_element(r.coarse_worst_decay.begin(), r.coarse_worst_decay.end());
  EXPECT_GE(r.worst_decay, coarse_best - 1e-12);
  EXPECT_NEAR(r.certified_worst_decay, r.worst_decay, 1e-8);
  EXPECT_GT(r.worst_decay, 0.0);
  EXPECT_GE(r.x, s.x_min);
  EXPECT_LE(r.x, s.x_max);
  EXPECT_GE(r.y, s.y_min);
  EXPECT_LE(r.y, s.y_max);
  ASSERT_GE(r.margins.size(), 2u);
  for (const auto& m : r.margins) EXPECT_GT(m.critical_delay, s.delay_max);  // stable on the whole delay range
  // no better point on a local stencil around the optimum (up to the Nelder–Mead tolerance)
  const double h = 0.01;
  for (auto [dx, dy] : {std::pair{h, 0.0}, std::pair{-h, 0.0}, std::pair{0.0, h}, std::pair{0.0, -h}}) {
    const double x = std::clamp(r.x + dx, s.x_min, s.x_max), y = std::clamp(r.y + dy, s.y_min, s.y_max);
    EXPECT_LE(worst_case_decay(s, x, y), r.worst_decay + 1e-3);
  }
}

TEST(RobustTuning, BadInput) {
  RobustTuningSpec s = spec(false);
  s.gain_ratio_max = 0.5;
  try {
    robust_tuning(s);
    ADD_FAILURE();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "gain_ratio_max");
  }
  s = spec(false);
  s.delay_max = -1.0;
  EXPECT_THROW(worst_case_decay(s, 0.1, 0.1), InvalidParameter);
  s = spec(false);
  EXPECT_THROW(worst_case_decay(s, std::nan(""), 0.1), InvalidParameter);
}
