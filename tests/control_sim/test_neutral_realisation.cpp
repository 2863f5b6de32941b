// Fig. 7 of seed 2: the N = ∞ neutral realisation (eqs. 32–33) vs the truncated bank (eq. 15),
// docs/theory-control.md#neutral-realisation.
//  * convergence of the truncated controller to the neutral one as N grows (∝ 1/N,
//    docs/theory-control.md#simulation: 0.32, 0.081 for
//    N = 10, 40 over 40 periods),
//  * long-run residual of the first harmonic: first order in h for the neutral form, third order for the bank
//    (docs/theory-control.md#simulation: 1.04e-3/5.2e-4/2.6e-4 vs 4.6e-6/5.7e-7/7.2e-8 at 500/1000/2000
//    steps per period),
//  * the cause: the closed-loop quasi-polynomial of the neutral realisation vanishes at s = iΩ and s = 0
//    (cancelled factors, docs/theory-control.md#infinite-bank), i.e. it has roots exactly on the imaginary axis.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "afmkit/control/closed_loop_simulation.hpp"
#include "afmkit/control/harmonic_analysis.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit::control;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kT;
using afmkit_test::fig5::kGamma;
const Plant& fig5_static() {
  static const Plant p(PlantKind::Static, kGamma, kOmega, 0.1 * kT, Disturbance::paper_example());
  return p;
}
SimulationOptions neutral_opts(int periods, int steps, int record = 0) {
  SimulationOptions o;
  o.periods = periods;
  o.steps_per_period = steps;
  o.record_every = record;
  return o;
}
}  // namespace

TEST(NeutralRealisation, TruncatedBankConvergesToItAsOneOverN) {
  const InfiniteBank inf(kOmega, 0.1, -0.1, kGamma);
  const auto un = simulate_closed_loop(fig5_static(), inf, neutral_opts(40, 2000, 1)).series.u;
  double dev[2];
  int idx = 0;
  for (int n : {10, 40}) {
    const auto ut = simulate_closed_loop(fig5_static(), OscillatorBank::with_couplings(kOmega, n, 0.1, -0.1, kGamma),
                                         neutral_opts(40, 2000, 1)).series.u;
    ASSERT_EQ(ut.size(), un.size());
    double d = 0.0;
    for (std::size_t i = 0; i < un.size(); ++i) d = std::max(d, std::abs(ut[i] - un[i]));
    dev[idx++] = d;
  }
  EXPECT_GT(dev[0], 0.1);
  EXPECT_LT(dev[0], 1.0);                  // docs/theory-control.md#simulation: 0.32
  EXPECT_NEAR(dev[0] / dev[1], 4.0, 1.2);  // ∝ 1/N (docs/theory-control.md#simulation: 0.32/0.081 = 3.95)
}

TEST(NeutralRealisation, LongRunErrorIsFirstOrderInStepTruncatedIsThirdOrder) {
  const InfiniteBank inf(kOmega, 0.1, -0.1, kGamma);
  const auto bank = OscillatorBank::with_couplings(kOmega, 10, 0.1, -0.1, kGamma);
  double neutral[3], truncated[3];
  int i = 0;
  for (int m : {500, 1000, 2000}) {
    neutral[i] = simulate_closed_loop(fig5_static(), inf, neutral_opts(150, m)).report.residual_first_harmonic;
    truncated[i] = simulate_closed_loop(fig5_static(), bank, neutral_opts(150, m)).report.residual_first_harmonic;
    ++i;
  }
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(std::log2(neutral[j] / neutral[j + 1]), 1.0, 0.3) << j;      // O(h)
    EXPECT_NEAR(std::log2(truncated[j] / truncated[j + 1]), 3.0, 0.3) << j;  // O(h³)
  }
  // magnitudes as in docs/theory-control.md#simulation (random phases of f differ, so only the order of magnitude is
  // compared)
  EXPECT_GT(neutral[0], 3e-4);
  EXPECT_LT(neutral[0], 3e-3);
  EXPECT_GT(truncated[2], 2e-8);
  EXPECT_LT(truncated[2], 2e-7);
  EXPECT_GT(neutral[2], 1000.0 * truncated[2]);
}

TEST(NeutralRealisation, ClosedLoopHasRootsOnTheImaginaryAxis) {
  // Δ(s) = γ(𝒜 − ℬe^{−sT}) + e^{−sτ}𝒩(1 − e^{−sT}) (static plant), coefficients of eq. (31).
  const InfiniteBank inf(kOmega, 0.1, -0.1, kGamma);
  const auto a = inf.a_coefficients(), b = inf.b_coefficients();
  const auto nn = inf.n_coefficients();
  const double tau = 0.1 * kT;
  auto poly = [](const auto& c, std::complex<double> s) {
    std::complex<double> v = 0.0;
    for (int j = static_cast<int>(c.size()) - 1; j >= 0; --j) v = v * s + c[j];
    return v;
  };
  auto delta = [&](std::complex<double> s) {
    return kGamma * (poly(a, s) - poly(b, s) * std::exp(-s * kT)) +
           std::exp(-s * tau) * poly(nn, s) * (1.0 - std::exp(-s * kT));
  };
  const double scale = std::abs(delta({0.0, 0.5}));
  EXPECT_LT(std::abs(delta({0.0, kOmega})), 1e-12 * scale);
  EXPECT_LT(std::abs(delta({0.0, 0.0})), 1e-12 * scale);
  EXPECT_GT(std::abs(delta({-0.05, kOmega})), 1e-4 * scale);  // a genuine root, not identically small
}

TEST(NeutralRealisation, RejectsFirstHarmonicWithFirstOrderPlant) {
  const Plant plant(PlantKind::FirstOrder, kGamma, kOmega, 0.1 * kT, Disturbance::paper_example());
  const auto r = simulate_closed_loop(plant, InfiniteBank(kOmega, 0.1, -0.1, kGamma), neutral_opts(60, 2000)).report;
  EXPECT_FALSE(r.diverged);
  EXPECT_LT(r.residual_first_harmonic, 2e-3);
  // harmonics 2..8 of f are kept (N = ∞ bank); 0 and 2..8 compared with γ f_k/(γ + ikΩ)
  ASSERT_EQ(r.harmonics.size(), 8u);
  EXPECT_LT(r.max_harmonic_error, 2e-3);
}
