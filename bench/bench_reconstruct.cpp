// Speed of the force reconstructions with their round trips (docs/reconstruction.md#speed). Target (issue 25):
// a 1000-point curve reconstructed with its round trip ≤ 1 s.
//   FM: qPlus sensor (k = 1800 N/m, f0 = 25 kHz), exponential force (F0 = 1 nN, λ = 0.1 nm), A = 0.5 nm, 1000
//       points on [0.05, 2.05] nm; Sader–Jarvis and matrix, 8 noise realisations, round trip through the exact FM
//       orbits at 40 (the default) distances, or by the first-order formula at every point (…_first_order).
//   AM: k = 40 N/m, f0 = 300 kHz, Q = 400, A0 = 10 nm, DMT + vdW (R = 10 nm, E* = 1 GPa, A_H = 1e-19 J), 1000
//       separations on [6, 12] nm from afmkit's exact orbits; payam, round trip through exact orbits at 40 (the
//       default) and 100 separations.
// Counters: orbits (of the round trip), simulations (FM: one-period simulations of the orbits' Newton solves), the
// round-trip residual. table_period: one period of the FM round trip's table law (1000 knots) with and without
// sensitivities and orbit integrals, and the ratio of the steps (the cost of the round trip's Newton iterations:
// 27 before the sensitivities of a C¹ table were held relative to their floor, 8.8 after; docs/reconstruction.md#speed).
#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>

#include "afmkit/spectroscopy/reconstruct_am.hpp"
#include "afmkit/spectroscopy/reconstruct_fm.hpp"
#include "afmkit/impact/laws/table_law.hpp"
#include "afmkit/tapping/observer.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/simulation.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/units.hpp"

namespace {

namespace sp = afmkit::spectroscopy;

/// 1000 points of the first-order Δf of an exponential force (1 nN, decay 0.1 nm) over 2 nm, with 1 mHz of
/// deterministic "noise".
sp::FmCurve exponential_curve(const sp::FmSettings& s) {
  sp::FmCurve c;
  for (int i = 0; i < 1000; ++i) {
    const double z = 0.05e-9 + 2e-9 * i / 999.0;
    c.distance.push_back(z);
    c.frequency_shift.push_back(sp::exponential_force_frequency_shift(z, 1e-9, 0.1e-9, s) + 1e-3 * std::sin(7.0 * i));
  }
  return c;
}

void fm(benchmark::State& state, sp::FmMethod method, bool exact) {
  const sp::FmSettings s(1800.0, 25e3, 0.5e-9);
  const sp::FmCurve c = exponential_curve(s);
  sp::FmOptions o;
  o.method = method;
  o.exact_round_trip = exact;
  sp::FmReconstruction r;
  for (auto _ : state) r = sp::reconstruct_fm(c, s, o);
  state.counters["points"] = 1000;
  state.counters["orbits"] = r.round_trip_orbits;
  state.counters["simulations"] = static_cast<double>(r.round_trip_simulations);
  state.counters["residual_rms_Hz"] = r.residual_rms;
}

void am(benchmark::State& state) {
  const afmkit::tapping::PhysicalCantilever pc(40.0, 300.0, 400.0, 10.0, 1.0);
  const afmkit::impact::ForceLaw law(afmkit::impact::DmtLaw(1.0, 1.0, 10.0, 1e-19, 1e-19, 0.165));
  std::vector<double> l;
  for (int i = 0; i < 1000; ++i) l.push_back(6.0 + 6.0 * i / 999.0);
  const afmkit::tapping::TappingModel m(pc.cantilever(), pc.drive(), pc.normalised_law(law), l.back());
  afmkit::tapping::SweepOptions so;
  so.harmonic_balance = false;
  const auto sw = afmkit::tapping::sweep_instrument(m, l, so);
  sp::AmCurve c;
  for (const auto& p : sw.approach) {
    c.separation.push_back(p.separation * 1e-9);
    c.amplitude.push_back(p.metrics.amplitude * 1e-9);
    c.phase.push_back(p.metrics.phase);
  }
  const sp::AmSettings s(40.0, 300e3, 400.0, 10e-9);
  sp::AmOptions o;
  o.round_trip_points = static_cast<int>(state.range(0));
  sp::AmReconstruction r;
  for (auto _ : state) r = sp::reconstruct_am(c, s, o);
  state.counters["points"] = 1000;
  state.counters["round_trip_points"] = static_cast<double>(state.range(0));
  state.counters["orbits"] = r.round_trip_orbits;
  state.counters["rms_phase_rad"] = r.rms_phase;
  state.counters["rms_amplitude_ratio"] = r.rms_amplitude_ratio;
}

/// One period of the FM round trip's table law (the law reconstructed by Sader–Jarvis from the fm benchmark's curve:
/// 1000 knots over 2 nm) at separation 0.6 nm (turning-point gap ≈ 0.1 nm), without and with sensitivities, without
/// and with the orbit integrals of an FM evaluation.
void table_period(benchmark::State& state) {
  namespace tp = afmkit::tapping;
  const sp::FmSettings s(1800.0, 25e3, 0.5e-9);
  const sp::FmCurve c = exponential_curve(s);
  sp::FmOptions fo;
  fo.round_trip = false;
  const auto r = sp::reconstruct_fm(c, s, fo);
  const tp::PhysicalCantilever pc(1800.0, 25.0, 1e4, 0.5, 1.0);
  const tp::TappingModel model(pc.cantilever(), pc.drive(),
                               pc.normalised_law(afmkit::impact::make_law<afmkit::impact::TableLaw>(r.law, true)),
                               0.6);
  const tp::TipState start = tp::free_response_state(model);
  tp::SimulationOptions o;
  o.sensitivity = state.range(0) != 0;
  long steps = 0;
  for (auto _ : state) {
    if (state.range(1) != 0) {
      tp::OrbitIntegrals integrals(model.period() / 48.0);  // as an FM orbit's evaluation (fm_orbit.cpp)
      steps = tp::simulate(model, 0.0, start, model.period(), o, &integrals).stats.steps;
    } else {
      steps = tp::simulate(model, 0.0, start, model.period(), o).stats.steps;
    }
  }
  o.sensitivity = false;
  const long plain = tp::simulate(model, 0.0, start, model.period(), o).stats.steps;
  state.counters["steps"] = static_cast<double>(steps);
  state.counters["steps_ratio_to_plain"] = static_cast<double>(steps) / static_cast<double>(plain);
}

}  // namespace

BENCHMARK_CAPTURE(fm, sader_jarvis_1000, sp::FmMethod::sader_jarvis, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(fm, matrix_1000, sp::FmMethod::matrix, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(fm, sader_jarvis_1000_first_order, sp::FmMethod::sader_jarvis, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(fm, matrix_1000_first_order, sp::FmMethod::matrix, false)->Unit(benchmark::kMillisecond);
BENCHMARK(am)->Arg(40)->Arg(100)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(table_period)->ArgNames({"sensitivity", "integrals"})->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
