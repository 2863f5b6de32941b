// The simulation report above the bank's N (SimulationOptions::report_max_order): a harmonic of f above N is
// reported, its value equals an independent DFT of the recorded y over the last period and the frequency-domain
// closed loop S(ikΩ) f_k (loop.hpp, the same loop without simulation); by default the report stops at N.
#include <gtest/gtest.h>

#include <complex>
#include <numbers>

#include "afmkit/control/closed_loop_simulation.hpp"
#include "afmkit/control/loop.hpp"
#include "afmkit/core/error.hpp"

using namespace afmkit::control;

namespace {
constexpr double kOmegaOrders = 2.0, kRateOrders = 20.0 * kOmegaOrders;
// f = sin(Ωt) + 0.4 sin(4Ωt + 0.7): harmonic 4 above a bank of N = 2
Plant plant_with_fourth_harmonic() {
  return Plant(PlantKind::Static, kRateOrders, kOmegaOrders, 0.1 * 2.0 * std::numbers::pi / kOmegaOrders,
               Disturbance(0.0, {{1, 1.0, 0.0}, {4, 0.4, 0.7}}));
}
OscillatorBank bank() { return OscillatorBank::with_couplings(kOmegaOrders, 2, 0.1 * kOmegaOrders, -0.1 * kOmegaOrders, kRateOrders); }
}  // namespace

TEST(ReportOrders, HarmonicAboveTheBankIsReportedAndMatchesDftAndFrequencyDomain) {
  SimulationOptions o;
  o.periods = 60;
  o.steps_per_period = 256;
  o.stepping = ControllerStepping::AdamsBashforth3;  // third order: ZOH's half-step lag would show at k = 4
  o.record_every = 1;
  o.report_max_order = 6;
  const SimulationResult r = simulate_closed_loop(plant_with_fourth_harmonic(), bank(), o);
  EXPECT_EQ(r.report.bank_max_order, 2);
  ASSERT_EQ(r.report.harmonics.back().order, 6);
  const int m = o.steps_per_period;
  const auto& y = r.series.y;
  ASSERT_EQ(y.size(), static_cast<std::size_t>(o.periods * m));
  const std::complex<double> f4 = std::complex<double>(0.0, -0.4) * std::exp(std::complex<double>(0.0, 0.7));
  const LoopSpec loop(bank(), PlantKind::Static, kRateOrders, 0.1 * 2.0 * std::numbers::pi / kOmegaOrders);
  double above = 0.0;
  for (const HarmonicComparison& h : r.report.harmonics) {
    std::complex<double> dft = 0.0;  // (2/M) Σ y_n e^{−2πikn/M} over the last period (k = 0: the mean)
    for (int n = 0; n < m; ++n)
      dft += y[y.size() - m + n] * std::exp(std::complex<double>(0.0, -2.0 * std::numbers::pi * h.order * n / m));
    dft *= (h.order == 0 ? 1.0 : 2.0) / m;
    EXPECT_NEAR(std::abs(h.value - dft), 0.0, 1e-10) << "harmonic " << h.order;
    if (h.order > 2) above = std::max(above, h.error);
  }
  const HarmonicComparison& h4 = r.report.harmonics[3];  // orders 0, 2, 3, 4 (1 rejected)
  ASSERT_EQ(h4.order, 4);
  const std::complex<double> expected = disturbance_response(loop, {0.0, 4.0 * kOmegaOrders}) * f4;
  EXPECT_GT(std::abs(expected - f4), 1e-2);  // the controller changes what it does not model
  EXPECT_NEAR(std::abs(h4.value - expected), 0.0, 1e-4 * std::abs(f4));
  EXPECT_EQ(h4.target, f4);
  EXPECT_DOUBLE_EQ(r.report.max_harmonic_error_above, above);
  EXPECT_LT(r.report.max_harmonic_error, 1e-4);  // k ≤ N: kept (AB3 floor)
}

TEST(ReportOrders, DefaultStopsAtTheBankAndOrdersAtOrAboveNyquistAreRefused) {
  SimulationOptions o;
  o.periods = 2;
  o.steps_per_period = 64;
  o.record_every = 0;
  const SimulationResult r = simulate_closed_loop(plant_with_fourth_harmonic(), bank(), o);
  EXPECT_EQ(r.report.harmonics.back().order, 2);
  EXPECT_TRUE(std::isnan(r.report.max_harmonic_error_above));
  o.report_max_order = 32;  // M/2
  try {
    ClosedLoopSimulation(plant_with_fourth_harmonic(), bank(), o);
    ADD_FAILURE();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "report_max_order");
    EXPECT_NE(std::string(e.what()).find("must be an integer in [0, 31]"), std::string::npos) << e.what();
  }
  o.report_max_order = 31;
  EXPECT_NO_THROW(ClosedLoopSimulation(plant_with_fourth_harmonic(), bank(), o));
}
