// Real-time filter: its discretisation against the dense matrix exponential and adaptive Runge–Kutta, its output
// against the closed-loop simulation (independent implementation of the same sampled controller), bumpless
// parameter changes, NaN skipping, save/restore, validation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "afmkit/control/closed_loop_simulation.hpp"
#include "afmkit/control/discretisation.hpp"
#include "afmkit/control/harmonic_analysis.hpp"
#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/core/error.hpp"
#include "sim_test_helpers.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit::control;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kT;
using afmkit_test::fig5::kGamma;
constexpr int kSteps = 2000;  // samples per rotation period
const double kFilterRate = kSteps / kT;

OscillatorBank fig5_filter_bank(int n = 10, double gain = kGamma) {
  return OscillatorBank::with_couplings(kOmega, n, 0.1, -0.1, gain);
}

/// Static plant (3) around the filter, τ = d samples; returns the outputs; f = paper example.
struct Loop {
  Disturbance f = Disturbance::paper_example();
  std::vector<double> y_hist;
  int delay = 200;
  double measure(long n) const {
    if (n - delay < 0) return f(kOmega * (n - delay) / kFilterRate);
    return y_hist[static_cast<std::size_t>(n - delay)];
  }
  /// run `count` samples; returns u per sample
  std::vector<double> run(RealtimeFilter& filter, long count, long skip_every = 0) {
    std::vector<double> u(static_cast<std::size_t>(count));
    for (long i = 0; i < count; ++i) {  // same order as the simulation: m_n = y_{n−d}, u_n, then y_n = f_n + u_n/γ
      const long n = static_cast<long>(y_hist.size());
      double m = measure(n);
      if (skip_every > 0 && n % skip_every == skip_every - 1) m = std::numeric_limits<double>::quiet_NaN();
      const double un = filter.step(m);
      u[static_cast<std::size_t>(i)] = un;
      y_hist.push_back(f(kOmega * n / kFilterRate) + un / kGamma);
    }
    return u;
  }
  double first_harmonic_of_last_period() const {
    std::vector<double> last(y_hist.end() - kSteps, y_hist.end());
    return std::abs(fourier_coefficients(last, 1)[1]);
  }
};
}  // namespace

TEST(RealtimeFilter, ModalFormEqualsDenseMatrixExponential) {
  for (int n : {1, 3, 10, 50}) {
    const auto bank = fig5_filter_bank(n);
    const double fs = 40.0 * n / kT;
    RealtimeFilter f(bank, fs);
    EXPECT_TRUE(f.uses_modal_form()) << n;
    const ZeroOrderHold zoh = zero_order_hold(bank.state_matrix(), bank.input_vector(), 1.0 / fs);
    EXPECT_LT((f.transition_matrix() - zoh.transition).norm(), 1e-11) << n;
    EXPECT_LT((f.input_vector() - zoh.input.col(0)).norm(), 1e-12 * zoh.input.norm()) << n;
    EXPECT_LT((f.output_vector() + bank.output_vector()).norm(), 1e-10 * kGamma) << n;
  }
}

TEST(RealtimeFilter, DefectiveControllerFallsBackToDenseForm) {
  // N = 2, only harmonic 1 rejected: the kept loop (x0, x2, z2) has the characteristic polynomial
  // s³ + (a0 + a2)s² + (4Ω² − 2Ω b2)s + 4Ω² a0 (eq. 18 with N = 2); a0 = 1/4, a2 = 11/4, b2 = 1/2 (Ω = 1) make it
  // (s + 1)³: a Jordan block, no eigenvector basis. The filter must still be exactly e^{Ah}.
  const OscillatorBank bank(1.0, 0.25, {0.3, 2.75}, {0.1, 0.5}, 5.0, {1});
  const double fs = 50.0 / kT;
  RealtimeFilter f(bank, fs);
  EXPECT_FALSE(f.uses_modal_form());
  const ZeroOrderHold zoh = zero_order_hold(bank.state_matrix(), bank.input_vector(), 1.0 / fs);
  EXPECT_LT((f.transition_matrix() - zoh.transition).norm(), 1e-14);
  Eigen::VectorXd z0 = Eigen::VectorXd::LinSpaced(bank.state_size(), 0.2, -0.6);
  f.set_controller_state(z0);
  EXPECT_NEAR(f.step(0.3), (-bank.output_vector() * z0)(0), 1e-14);
  const Eigen::VectorXd ref = simref::integrate_linear(bank.state_matrix(), bank.input_vector() * 0.3, z0, 1.0 / fs);
  EXPECT_LT((f.controller_state() - ref).norm(), 1e-11);
  // save/restore and skipping work in the dense form too
  const auto st = f.save_state();
  const double u1 = f.step(std::nan("")), u2 = f.step(0.1);
  f.restore_state(st);
  EXPECT_EQ(f.step(std::nan("")), u1);
  EXPECT_EQ(f.step(0.1), u2);
}

TEST(RealtimeFilter, ZeroOrderHoldMatchesRungeKuttaWithHeldSample) {
  const auto bank = OscillatorBank::with_couplings(kOmega, 5, 0.2, 0.05, 15.0, {1, 3});
  const double fs = 37.0 / kT, h = 1.0 / fs, m = 0.81;
  RealtimeFilter f(bank, fs);
  Eigen::VectorXd z0 = Eigen::VectorXd::LinSpaced(bank.state_size(), 0.5, -0.8);
  f.set_controller_state(z0);
  const double u = f.step(m);
  EXPECT_NEAR(u, (-bank.output_vector() * z0)(0), 1e-13);  // u_n = −K Σ_rej x_k(t_n)
  const Eigen::VectorXd ref = simref::integrate_linear(bank.state_matrix(), bank.input_vector() * m, z0, h);
  EXPECT_LT((f.controller_state() - ref).norm(), 1e-11);
}

TEST(RealtimeFilter, BlockFormMatchesRungeKuttaOfEachOscillatorWithHeldError) {
  // ż = A0 z + b e with e = m − c_eᵀ z(t_n) held (no coupling inside the step)
  const auto bank = fig5_filter_bank(6);
  const double fs = 50.0 / kT, h = 1.0 / fs, m = -0.4;
  RealtimeFilter f(bank, fs, SampledForm::BlockZeroOrderHold);
  EXPECT_FALSE(f.uses_modal_form());
  Eigen::VectorXd z0 = Eigen::VectorXd::LinSpaced(bank.state_size(), -0.3, 0.9);
  f.set_controller_state(z0);
  f.step(m);
  const Eigen::MatrixXd a0 = bank.state_matrix() + bank.input_vector() * bank.error_vector();  // A0 = A + b c_eᵀ
  const double e = m - (bank.error_vector() * z0)(0);
  const Eigen::VectorXd ref = simref::integrate_linear(a0, bank.input_vector() * e, z0, h);
  EXPECT_LT((f.controller_state() - ref).norm(), 1e-11);
}

TEST(RealtimeFilter, OutputEqualsClosedLoopSimulationWithSameDiscretisation) {
  const Plant plant(PlantKind::FirstOrder, kGamma, kOmega, 0.1 * kT, Disturbance::paper_example());
  for (auto [stepping, form] : {std::pair{ControllerStepping::ZeroOrderHold, SampledForm::ZeroOrderHold},
                                std::pair{ControllerStepping::BlockZeroOrderHold, SampledForm::BlockZeroOrderHold}}) {
    SimulationOptions o;
    o.periods = 10;
    o.steps_per_period = kSteps;
    o.stepping = stepping;
    o.record_every = 1;
    const auto res = simulate_closed_loop(plant, fig5_filter_bank(), o);
    RealtimeFilter f(fig5_filter_bank(), kFilterRate, form);
    double max_diff = 0.0, max_u = 0.0;
    for (std::size_t n = 0; n < res.series.m.size(); ++n) {
      max_diff = std::max(max_diff, std::abs(f.step(res.series.m[n]) - res.series.u[n]));
      max_u = std::max(max_u, std::abs(res.series.u[n]));
    }
    EXPECT_GT(max_u, 10.0);
    EXPECT_LT(max_diff, 1e-10 * max_u) << static_cast<int>(form);
  }
}

TEST(RealtimeFilter, ClosedLoopRejectsFirstHarmonicToRounding) {
  for (auto form : {SampledForm::ZeroOrderHold, SampledForm::BlockZeroOrderHold}) {
    RealtimeFilter f(fig5_filter_bank(), kFilterRate, form);
    Loop loop;
    loop.run(f, 60L * kSteps);
    EXPECT_LT(loop.first_harmonic_of_last_period(), 1e-10);
  }
}

TEST(RealtimeFilter, BumplessParameterChange) {
  RealtimeFilter f(fig5_filter_bank(), kFilterRate);
  Loop loop;
  loop.run(f, 20L * kSteps + kSteps / 4);  // a quarter period in: u ≈ −γ F1 sin(Ωt) is near its peak
  // reference: a copy continuing with the old parameters
  RealtimeFilter ref = f;
  Loop loop_ref = loop;
  const double next_old = loop_ref.run(ref, 1)[0];
  // change K (×1.6), α, β, N and the sample rate at once
  f.reconfigure(OscillatorBank::with_couplings(kOmega, 12, 0.15, -0.05, 1.6 * kGamma), 1.1 * kFilterRate);
  const double next_new = loop.run(f, 1)[0];
  EXPECT_GT(std::abs(next_old), 1.0);
  EXPECT_NEAR(next_new, next_old, 1e-9 * std::abs(next_old));  // u = −K x1 continuous
  // gain only, then the loop keeps converging (K = γ/2 is still stable)
  RealtimeFilter g(fig5_filter_bank(), kFilterRate);
  Loop loop2;
  loop2.run(g, 15L * kSteps + kSteps / 4);
  RealtimeFilter g_ref = g;
  Loop loop2_ref = loop2;
  const double a = loop2_ref.run(g_ref, 1)[0];
  g.set_gain(0.5 * kGamma);
  EXPECT_GT(std::abs(a), 1.0);
  EXPECT_NEAR(loop2.run(g, 1)[0], a, 1e-10 * std::abs(a));
  EXPECT_EQ(g.controller().gain(), 0.5 * kGamma);
  loop2.run(g, 60L * kSteps);
  EXPECT_LT(loop2.first_harmonic_of_last_period(), 1e-9);
}

TEST(RealtimeFilter, InvalidReconfigurationLeavesFilterUnchanged) {
  RealtimeFilter f(fig5_filter_bank(), kFilterRate);
  Loop loop;
  loop.run(f, 3L * kSteps);
  const auto saved = f.save_state();
  EXPECT_THROW(f.reconfigure(fig5_filter_bank(), 2.0 / kT), afmkit::InvalidParameter);  // Nyquist
  EXPECT_EQ(f.save_state(), saved);
  EXPECT_EQ(f.sample_rate(), kFilterRate);
}

TEST(RealtimeFilter, NonFiniteSamplesAreSkipped) {
  RealtimeFilter f(fig5_filter_bank(), kFilterRate);
  Loop loop;
  loop.run(f, 1000);
  const double before = f.last_output();
  EXPECT_EQ(f.step(std::numeric_limits<double>::quiet_NaN()), before);
  EXPECT_EQ(f.step(std::numeric_limits<double>::infinity()), before);
  EXPECT_EQ(f.step(-std::numeric_limits<double>::infinity()), before);
  EXPECT_EQ(f.skipped_samples(), 3u);
  EXPECT_TRUE(f.controller_state().allFinite());
  // a loop with every 97th sample lost still converges (the oscillators keep their phase)
  for (auto form : {SampledForm::ZeroOrderHold, SampledForm::BlockZeroOrderHold}) {
    RealtimeFilter g(fig5_filter_bank(), kFilterRate, form);
    Loop l;
    l.run(g, 60L * kSteps, 97);
    EXPECT_EQ(g.skipped_samples(), static_cast<std::uint64_t>(60L * kSteps / 97));
    EXPECT_TRUE(g.controller_state().allFinite());
    EXPECT_LT(l.first_harmonic_of_last_period(), 1e-3);
  }
}

TEST(RealtimeFilter, SaveRestoreReproducesOutputsBitForBit) {
  for (auto form : {SampledForm::ZeroOrderHold, SampledForm::BlockZeroOrderHold}) {
    RealtimeFilter f(fig5_filter_bank(), kFilterRate, form);
    Loop loop;
    loop.run(f, 1234);
    f.step(std::numeric_limits<double>::quiet_NaN());
    const std::vector<double> state = f.save_state();
    ASSERT_EQ(state.size(), f.state_size());
    std::vector<double> inputs;
    for (int i = 0; i < 500; ++i) inputs.push_back(std::sin(0.01 * i) + 0.3 * std::cos(0.07 * i));
    std::vector<double> out1;
    for (double m : inputs) out1.push_back(f.step(m));
    RealtimeFilter g(fig5_filter_bank(), kFilterRate, form);  // fresh filter, same configuration
    g.restore_state(state);
    EXPECT_EQ(g.skipped_samples(), 1u);
    for (std::size_t i = 0; i < inputs.size(); ++i) ASSERT_EQ(g.step(inputs[i]), out1[i]) << i;
    f.restore_state(state);  // and the same filter rewound
    for (std::size_t i = 0; i < inputs.size(); ++i) ASSERT_EQ(f.step(inputs[i]), out1[i]) << i;
  }
}

TEST(RealtimeFilter, RestoreIntoOtherConfigurationCarriesPhysicalState) {
  RealtimeFilter f(fig5_filter_bank(), kFilterRate);
  Loop loop;
  loop.run(f, 4321);
  const Eigen::VectorXd z = f.controller_state();
  RealtimeFilter g(fig5_filter_bank(10, 2.0 * kGamma), 0.5 * kFilterRate, SampledForm::BlockZeroOrderHold);
  g.restore_state(f.save_state());
  EXPECT_LT((g.controller_state() - z).norm(), 1e-12 * z.norm());
}

TEST(RealtimeFilter, MalformedStateIsRejected) {
  RealtimeFilter f(fig5_filter_bank(), kFilterRate);
  auto state = f.save_state();
  auto bad = state;
  bad[0] = 1.0;
  EXPECT_THROW(f.restore_state(bad), afmkit::InvalidParameter);
  bad = state;
  bad.pop_back();
  EXPECT_THROW(f.restore_state(bad), afmkit::InvalidParameter);
  bad = state;
  bad[12] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(f.restore_state(bad), afmkit::InvalidParameter);
  std::vector<double> small(3);
  EXPECT_THROW(f.save_state(small), afmkit::InvalidParameter);
}

TEST(RealtimeFilter, ResetAndBlockProcessing) {
  RealtimeFilter f(fig5_filter_bank(), kFilterRate), g(fig5_filter_bank(), kFilterRate);
  std::vector<double> in(300), out(300);
  for (int i = 0; i < 300; ++i) in[i] = std::sin(0.02 * i);
  f.step_block(in, out);
  for (int i = 0; i < 300; ++i) EXPECT_EQ(out[i], g.step(in[i]));
  f.reset();
  EXPECT_EQ(f.controller_state().norm(), 0.0);
  EXPECT_EQ(f.last_output(), 0.0);
  EXPECT_EQ(f.samples(), 0u);
  f.step_block(in, in);  // in place
  EXPECT_EQ(in[299], out[299]);
}

TEST(RealtimeFilter, SampleRateMustSatisfyNyquist) {
  // N Ω < π f_s: N = 10, Ω = 1 ⇒ f_s > 10/π = 3.18
  try {
    RealtimeFilter f(fig5_filter_bank(), 3.0);
    ADD_FAILURE();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "sample_rate");
    EXPECT_NE(std::string(e.what()).find("Nyquist"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("3.18"), std::string::npos);
  }
  EXPECT_NO_THROW(RealtimeFilter(fig5_filter_bank(), 3.2));
  EXPECT_THROW(RealtimeFilter(fig5_filter_bank(), std::nan("")), afmkit::InvalidParameter);
  EXPECT_THROW(RealtimeFilter(fig5_filter_bank(), -5.0), afmkit::InvalidParameter);
}
