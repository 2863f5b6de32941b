// Speed of the preparation of a measured force curve (docs/spectroscopy.md): prepare() of a curve of 10^5 samples
// (5·10^4 per segment: approach and retract), deflection in volts, with calibration, baseline fit, Hertz fit of the
// contact point, binning and events. Target (issue 25): ≤ 0.2 s. The curve: a Hertz contact (E = 100 kPa, R = 2 µm,
// k = 0.1 N/m, retract 20 % lower), baseline offset and tilt, Gaussian noise of a fixed seed; made from the tip
// position x (z = x − F(x)/k is monotone because F decreases with x).
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "afmkit/spectroscopy/prepare.hpp"

namespace {

using namespace afmkit;

io::curves::RawCurve curve(std::size_t per_segment) {
  constexpr double k = 0.1, invols = 50e-9, xc = 2e-6, noise = 2e-3;
  const double c = 4.0 / 3.0 * 100e3 / 0.75 * std::sqrt(2e-6);
  io::curves::RawCurve raw;
  raw.origin = "benchmark";
  raw.metadata.spring_constant = k;
  raw.metadata.invols = invols;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, noise);
  for (int branch = 0; branch < 2; ++branch) {
    io::curves::Segment s;
    s.kind = branch == 0 ? io::curves::SegmentKind::approach : io::curves::SegmentKind::retract;
    for (std::size_t i = 0; i < per_segment; ++i) {
      const double t = static_cast<double>(i) / static_cast<double>(per_segment - 1);
      const double x = branch == 0 ? xc + 3e-6 - t * 3.43e-6 : xc - 0.43e-6 + t * 3.43e-6;
      const double f = (branch == 0 ? 1.0 : 0.8) * c * std::pow(std::max(0.0, xc - x), 1.5);
      const double z = x - f / k;
      s.height.push_back(z);
      s.deflection_volts.push_back((f / k + 20e-9 + 4e-3 * z) / invols + n(rng));
    }
    raw.segments.push_back(std::move(s));
  }
  return raw;
}

void BM_Prepare(benchmark::State& state) {
  const std::vector<io::curves::RawCurve> curves{curve(static_cast<std::size_t>(state.range(0)) / 2)};
  spectroscopy::PrepareOptions options;
  options.contact.fit.tip_radius = 2e-6;
  double e = 0;
  int evaluations = 0;
  for (auto _ : state) {
    const spectroscopy::PreparedCurve p = spectroscopy::prepare(curves, options);
    e = p.curves[0].contact.fit->youngs_modulus;
    evaluations = p.curves[0].contact.fit->evaluations;
    benchmark::DoNotOptimize(p.approach.force.data());
  }
  state.counters["samples"] = static_cast<double>(state.range(0));
  state.counters["E_kPa"] = e / 1e3;
  state.counters["fit_evaluations"] = evaluations;
}
BENCHMARK(BM_Prepare)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
