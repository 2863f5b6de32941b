// Closed-loop simulation against independent results: the analytic steady state
// (docs/theory-control.md#oscillator-bank: first harmonic removed, harmonics 0, 2..N equal to f_k or γ f_k/(γ + ikΩ)),
// the rightmost root of the one-oscillator quasi-polynomial (eq. 12, Newton), a Runge–Kutta integration of plant (1)
// between samples, and input validation.
#include <gtest/gtest.h>

#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <numbers>

#include "afmkit/control/closed_loop_simulation.hpp"
#include "afmkit/control/harmonic_analysis.hpp"
#include "afmkit/core/error.hpp"
#include "sim_test_helpers.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit::control;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kT;
using afmkit_test::fig5::kGamma;

OscillatorBank fig5_bank(double gain = kGamma) { return OscillatorBank::with_couplings(kOmega, 10, 0.1, -0.1, gain); }

Plant fig5_plant(PlantKind kind, double delay_fraction) {
  return Plant(kind, kGamma, kOmega, delay_fraction * kT, Disturbance::paper_example());
}

SimulationOptions opts(int periods, int steps, ControllerStepping s = ControllerStepping::AdamsBashforth3,
                       int record = 0) {
  SimulationOptions o;
  o.periods = periods;
  o.steps_per_period = steps;
  o.stepping = s;
  o.record_every = record;
  return o;
}

template <class F>
void expect_invalid(F&& f, const std::string& parameter, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "no exception for " << parameter;
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), parameter) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}
}  // namespace

class Ab3SteadyState : public ::testing::TestWithParam<std::tuple<PlantKind, double>> {};

TEST_P(Ab3SteadyState, FirstHarmonicRemovedOthersPreserved) {
  const auto [kind, tau] = GetParam();
  const Plant plant = fig5_plant(kind, tau);
  const auto res = simulate_closed_loop(plant, fig5_bank(), opts(60, 2000));
  const auto& r = res.report;
  ASSERT_FALSE(r.diverged);
  // AB3 integrator floor: O(h³), docs/theory-control.md#simulation reports 7.15e-8 at 2000 steps per period.
  EXPECT_LT(r.residual_first_harmonic, 2e-7);
  ASSERT_EQ(r.harmonics.size(), 10u);  // k = 0, 2..10
  for (const auto& hc : r.harmonics) {
    EXPECT_LT(hc.error, 1e-6) << "harmonic " << hc.order;
    // target computed independently of the report: f_k (eq. 3) or γ f_k/(γ + ikΩ) (eq. 1)
    const std::complex<double> fk = disturbance_harmonic(plant.disturbance, hc.order);
    const std::complex<double> expect =
        kind == PlantKind::Static ? fk : kGamma * fk / std::complex<double>(kGamma, hc.order * kOmega);
    EXPECT_LT(std::abs(hc.value - expect), 1e-6) << "harmonic " << hc.order;
  }
  // u_1 = −γ f_1 for both plants (y_1 = 0 ⇒ γ f_1 + u_1 = 0)
  const std::complex<double> u1 = -kGamma * disturbance_harmonic(plant.disturbance, 1);
  EXPECT_LT(std::abs(r.control_first_harmonic - u1), 1e-5 * kGamma);
  EXPECT_LT(r.growth_rate, -0.05);  // converging
}

INSTANTIATE_TEST_SUITE_P(PlantsAndDelays, Ab3SteadyState,
                         ::testing::Combine(::testing::Values(PlantKind::Static, PlantKind::FirstOrder),
                                            ::testing::Values(0.0, 0.1, 0.2)));

TEST(ClosedLoopSimulation, IntegratorFloorIsThirdOrderInStep) {
  const Plant plant = fig5_plant(PlantKind::Static, 0.1);
  const double r1000 = simulate_closed_loop(plant, fig5_bank(), opts(60, 1000)).report.residual_first_harmonic;
  const double r2000 = simulate_closed_loop(plant, fig5_bank(), opts(60, 2000)).report.residual_first_harmonic;
  EXPECT_NEAR(std::log2(r1000 / r2000), 3.0, 0.25);
}

TEST(ClosedLoopSimulation, ZeroOrderHoldRemovesFirstHarmonicExactly) {
  for (auto kind : {PlantKind::Static, PlantKind::FirstOrder}) {
    const Plant plant = fig5_plant(kind, 0.1);
    const auto zoh = simulate_closed_loop(plant, fig5_bank(), opts(60, 2000, ControllerStepping::ZeroOrderHold));
    EXPECT_LT(zoh.report.residual_first_harmonic, 1e-10);  // exact internal model: poles e^{±iΩh}
    EXPECT_LT(zoh.report.max_harmonic_error, 1e-6);        // zeros of the sampled controller: O(h²) off
    const auto blk = simulate_closed_loop(plant, fig5_bank(), opts(60, 2000, ControllerStepping::BlockZeroOrderHold));
    EXPECT_LT(blk.report.residual_first_harmonic, 1e-10);
    EXPECT_LT(blk.report.max_harmonic_error, 1e-10);  // kept oscillators keep their poles e^{±ikΩh}: exact
  }
}

TEST(ClosedLoopSimulation, GainMismatchStillRejects) {
  // K = γ̂ ≠ γ (docs/theory-control.md#simulation: K = 0.5γ and 2γ still converge)
  const Plant plant = fig5_plant(PlantKind::Static, 0.1);
  for (double rho : {0.5, 2.0}) {
    const auto r = simulate_closed_loop(plant, fig5_bank(rho * kGamma), opts(80, 2000)).report;
    EXPECT_LT(r.residual_first_harmonic, 1e-6) << rho;
    EXPECT_LT(r.max_harmonic_error, 1e-6) << rho;
  }
}

TEST(ClosedLoopSimulation, OffGridAndSlowlyVaryingDelay) {
  // Constant delay between grid points (cubic interpolation of the history): same steady state.
  const double h = kT / 2000.0;
  const Plant off(PlantKind::FirstOrder, kGamma, kOmega, 0.1 * kT + 0.37 * h, Disturbance::paper_example());
  const auto r = simulate_closed_loop(off, fig5_bank(), opts(60, 2000)).report;
  EXPECT_LT(r.residual_first_harmonic, 2e-7);
  EXPECT_LT(r.max_harmonic_error, 1e-6);
  // τ(t) = 0.1T + 0.03T sin(0.02Ω t): the loop tracks the drifting delay; the residual is set by the drift rate.
  const Plant vary(PlantKind::FirstOrder, kGamma, kOmega, 0.1 * kT, Disturbance::paper_example(), 0.03 * kT, 0.02);
  const auto rv = simulate_closed_loop(vary, fig5_bank(), opts(80, 2000)).report;
  EXPECT_FALSE(rv.diverged);
  EXPECT_LT(rv.residual_first_harmonic, 1e-3);
  EXPECT_LT(rv.max_harmonic_error, 1e-2);
}

TEST(ClosedLoopSimulation, FirstOrderPlantStepIsExact) {
  // ZOH controller ⇒ u is held over each step; integrate ẏ = −γ(y − f) + u_n by adaptive RK between the samples.
  const Plant plant = fig5_plant(PlantKind::FirstOrder, 0.1);
  const auto res = simulate_closed_loop(plant, fig5_bank(), opts(3, 400, ControllerStepping::ZeroOrderHold, 1));
  const auto& s = res.series;
  ASSERT_EQ(s.t.size(), 1200u);
  namespace odeint = boost::numeric::odeint;
  double y = s.y[0], max_err = 0.0;
  for (std::size_t n = 0; n + 1 < s.t.size(); ++n) {
    const double u = s.u[n];
    auto rhs = [&](const double& x, double& dx, double t) {
      dx = -kGamma * (x - plant.disturbance(kOmega * t)) + u;
    };
    odeint::integrate_adaptive(odeint::make_controlled<odeint::runge_kutta_dopri5<double>>(1e-14, 1e-14), rhs, y,
                               s.t[n], s.t[n + 1], 1e-4);
    max_err = std::max(max_err, std::abs(y - s.y[n + 1]));
    y = s.y[n + 1];
  }
  EXPECT_LT(max_err, 1e-12);
  // initial condition: uncontrolled steady state; measurement before the start = uncontrolled history
  EXPECT_NEAR(s.y[0], uncontrolled_output(plant, 0.0), 1e-15);
  EXPECT_NEAR(s.m[0], uncontrolled_output(plant, -0.1 * kT), 1e-12);
  EXPECT_NEAR(s.target[7], target_output(plant, s.t[7], std::vector<int>{1}), 1e-12);
}

TEST(ClosedLoopSimulation, GrowthRateEqualsRightmostRootAboveCriticalDelay) {
  // One oscillator (5),(6), (a, b) = (0.5, 0)Ω, K = γ, static plant (3): τ_c/T = 0.195
  // (docs/theory-control.md#delay-margin).
  const double a = 0.5 * kOmega;
  const auto [tau_c, nu] = simref::one_oscillator_critical_delay(kOmega, a, 1.0);
  EXPECT_NEAR(tau_c / kT, 0.195, 5e-4);
  const int steps = 2000;
  const double h = kT / steps;
  const Disturbance f(0.0, {{1, 1.0, 0.0}});
  const auto bank = OscillatorBank::single(kOmega, a, 0.0, kGamma);
  {
    const double tau = std::round(1.03 * tau_c / h) * h;
    const std::complex<double> s = simref::one_oscillator_root(kOmega, a, 0.0, 1.0, tau, {0.0, nu});
    ASSERT_GT(s.real(), 0.0);
    const auto r = simulate_closed_loop(Plant(PlantKind::Static, kGamma, kOmega, tau, f), bank, opts(200, steps)).report;
    EXPECT_NEAR(r.growth_rate, s.real(), 0.03 * s.real()) << "root " << s;
  }
  {
    const double tau = std::round(0.97 * tau_c / h) * h;
    const std::complex<double> s = simref::one_oscillator_root(kOmega, a, 0.0, 1.0, tau, {0.0, nu});
    ASSERT_LT(s.real(), 0.0);
    const auto r = simulate_closed_loop(Plant(PlantKind::Static, kGamma, kOmega, tau, f), bank, opts(200, steps)).report;
    EXPECT_LT(r.growth_rate, 0.0);
    EXPECT_NEAR(r.growth_rate, s.real(), 0.05 * std::abs(s.real())) << "root " << s;
  }
}

TEST(ClosedLoopSimulation, FirstOrderPlantGrowthRateMatchesRootWithDenseAb3Output) {
  // Plant (1), one oscillator (a, b) = (0.5, 0)Ω, K = γ, τ = 0.25T: closed-loop poles solve
  // (s² + Ω²)(s + γ) + K e^{−sτ}(a s − bΩ) = 0 (Newton). AB3 feeds the plant its dense output (u cubic in t), so
  // the growth rate is right already at 500 steps per period; with u held (zoh) it is off by O(h).
  const double a = 0.5 * kOmega, tau = 0.25 * kT;
  std::complex<double> s(0.1, 1.2);
  for (int it = 0; it < 60; ++it) {
    const std::complex<double> e = std::exp(-s * tau);
    const std::complex<double> g = (s * s + kOmega * kOmega) * (s + kGamma) + kGamma * e * a * s;
    const std::complex<double> dg =
        2.0 * s * (s + kGamma) + (s * s + kOmega * kOmega) + kGamma * e * (a - tau * a * s);
    s -= g / dg;
  }
  ASSERT_GT(s.real(), 0.05);
  const Plant plant(PlantKind::FirstOrder, kGamma, kOmega, tau, Disturbance(0.0, {{1, 1.0, 0.0}}));
  const auto bank = OscillatorBank::single(kOmega, a, 0.0, kGamma);
  const double ab3 = simulate_closed_loop(plant, bank, opts(100, 500)).report.growth_rate;
  EXPECT_NEAR(ab3, s.real(), 3e-3 * s.real());
  const double z1 = simulate_closed_loop(plant, bank, opts(100, 1000, ControllerStepping::ZeroOrderHold)).report.growth_rate;
  const double z2 = simulate_closed_loop(plant, bank, opts(100, 2000, ControllerStepping::ZeroOrderHold)).report.growth_rate;
  EXPECT_NEAR((z1 - s.real()) / (z2 - s.real()), 2.0, 0.3);  // first order in h (sampling delay h/2 + h/2)
}

TEST(ClosedLoopSimulation, DelayBeyondPeriodIsFlaggedNotRejected) {
  const Plant plant(PlantKind::Static, kGamma, kOmega, 1.02 * kT, Disturbance::paper_example());
  const auto r = simulate_closed_loop(plant, OscillatorBank::with_couplings(kOmega, 10, 0.02, 0.0, kGamma),
                                      opts(3, 400)).report;
  EXPECT_TRUE(r.delay_exceeds_period);
  EXPECT_EQ(r.periods_completed, 3);
  const auto ok = simulate_closed_loop(fig5_plant(PlantKind::Static, 0.1), fig5_bank(), opts(2, 400)).report;
  EXPECT_FALSE(ok.delay_exceeds_period);
}

TEST(ClosedLoopSimulation, DivergenceStopsTheRun) {
  // (a, b) = (0.5, 0)Ω at τ = 0.45T: far beyond τ_c = 0.195T, grows fast; the run stops at |y| > 1e100.
  const Plant plant(PlantKind::Static, kGamma, kOmega, 0.45 * kT, Disturbance(0.0, {{1, 1.0, 0.0}}));
  const auto r = simulate_closed_loop(plant, OscillatorBank::single(kOmega, 4.0, 0.0, kGamma), opts(4000, 64)).report;
  EXPECT_TRUE(r.diverged);
  EXPECT_LT(r.periods_completed, 4000);
  EXPECT_TRUE(std::isinf(r.residual_first_harmonic));
}

TEST(ClosedLoopSimulation, TimeSeriesDecimation) {
  const auto res = simulate_closed_loop(fig5_plant(PlantKind::Static, 0.1), fig5_bank(),
                                        opts(4, 400, ControllerStepping::AdamsBashforth3, 10));
  ASSERT_EQ(res.series.t.size(), 160u);
  EXPECT_NEAR(res.series.t[1], 10 * kT / 400, 1e-14);
  const Disturbance f = Disturbance::paper_example();
  const double th = kOmega * res.series.t[5];
  EXPECT_NEAR(res.series.f_minus_first[5], f(th) - std::sin(th), 1e-12);  // F1 = 1, φ1 = 0
  EXPECT_EQ(res.report.envelope.size(), 4u);
  EXPECT_EQ(simulate_closed_loop(fig5_plant(PlantKind::Static, 0.1), fig5_bank(), opts(2, 400)).series.t.size(), 0u);
}

TEST(ClosedLoopSimulation, ProgressReportedOncePerPeriod) {
  long calls = 0, last = 0;
  ClosedLoopSimulation(fig5_plant(PlantKind::Static, 0.1), fig5_bank(), opts(5, 400)).run([&](long done, long total) {
    ++calls;
    last = done;
    EXPECT_EQ(total, 5);
  });
  EXPECT_EQ(calls, 5);
  EXPECT_EQ(last, 5);
}

TEST(ClosedLoopSimulationValidation, BadInputNamesParameterAndRange) {
  const Plant plant = fig5_plant(PlantKind::Static, 0.1);
  // AB3 outside its stability region: N = 10 needs M ≥ 87 (10Ωh < 0.7236)
  expect_invalid([&] { ClosedLoopSimulation(plant, fig5_bank(), opts(10, 60)); }, "steps_per_period", "AB3");
  // ...but the exact ZOH has no such limit; only Nyquist (M > 2N)
  EXPECT_NO_THROW(ClosedLoopSimulation(plant, fig5_bank(), opts(10, 60, ControllerStepping::ZeroOrderHold)));
  expect_invalid([&] { ClosedLoopSimulation(plant, fig5_bank(), opts(10, 20, ControllerStepping::ZeroOrderHold)); },
                 "steps_per_period", "Nyquist");
  expect_invalid([&] { ClosedLoopSimulation(plant, fig5_bank(), opts(0, 2000)); }, "periods", "[1,");
  expect_invalid([&] { OscillatorBank::with_couplings(kOmega, 0, 0.1, -0.1, kGamma); }, "harmonics", "[1,");
  expect_invalid([&] { OscillatorBank::with_couplings(kOmega, 10, std::nan(""), -0.1, kGamma); }, "alpha", "finite");
  expect_invalid([&] { Plant(PlantKind::Static, kGamma, kOmega, -0.1, Disturbance::paper_example()); }, "delay", ">= 0");
  expect_invalid([&] { Plant(PlantKind::Static, kGamma, 0.0, 0.1, Disturbance::paper_example()); },
                 "rotation_frequency", "> 0");
  // N = ∞: AB3 only, α > 0, Ω of controller = Ω of plant
  expect_invalid([&] { ClosedLoopSimulation(plant, InfiniteBank(kOmega, 0.1, -0.1, kGamma),
                                            opts(10, 2000, ControllerStepping::ZeroOrderHold)); },
                 "stepping", "ab3");
  expect_invalid([&] { ClosedLoopSimulation(plant, InfiniteBank(kOmega, -0.1, -0.1, kGamma), opts(10, 2000)); },
                 "alpha", "> 0");
  expect_invalid([&] { ClosedLoopSimulation(plant, InfiniteBank(1.1 * kOmega, 0.1, -0.1, kGamma), opts(10, 2000)); },
                 "rotation_frequency", "plant");
}
