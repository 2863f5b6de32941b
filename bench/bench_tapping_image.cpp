// `afmkit tapping image` speed (issue 27 target: 256 × 256 pixels, trace and retrace, quasi-static engine ≤ 2 s).
// The case of the command's defaults: k = 40 N/m, f0 = 300 kHz, Q = 100, A0 = 20 nm, DMT + van der Waals
// (E* = 1 GPa, R = 10 nm, A_H = 6.4e-20 J), 12 particles of radius 5 nm on a 1 µm square (512² sample map), line rate
// 1 Hz, feedback at 50 kHz (97 updates per pixel: 12.7 million controller updates). Two parts, timed apart:
// BM_OrbitMap (the instrument sweep of 300 + 300 separations, once per run) and BM_QuasiStaticImage (the scan on
// that map). Each prints its wall time in seconds (counter "seconds").
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>

#include "afmkit/impact/force_law.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/tapping/image/quasi_static.hpp"
#include "afmkit/tapping/units.hpp"

namespace {
namespace ti = afmkit::tapping::image;
using afmkit::tapping::PhysicalCantilever;

const PhysicalCantilever kCantilever(40.0, 300.0, 100.0, 20.0, 1.0);

afmkit::tapping::TappingModel bench_model() {
  const afmkit::impact::DmtLaw dmt(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165);
  return {kCantilever.cantilever(), kCantilever.drive(),
          kCantilever.normalised_law(afmkit::impact::ForceLaw(dmt)), 20.0};
}

ti::OrbitMap bench_map() {
  ti::OrbitMapOptions o;
  o.separation_min = 0.0;
  o.separation_max = 25.0;
  o.points = 300;
  o.sweep.transient.max_periods = 4000;
  return ti::OrbitMap::build(bench_model(), o);
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void BM_OrbitMap(benchmark::State& state) {
  for (auto _ : state) {
    const auto t = std::chrono::steady_clock::now();
    ti::OrbitMap map = bench_map();
    benchmark::DoNotOptimize(map);
    state.counters["seconds"] = seconds_since(t);
    std::printf("orbit map (300 + 300 separations): %.3f s, %zu branches\n", seconds_since(t), map.branches().size());
  }
}
BENCHMARK(BM_OrbitMap)->Iterations(1)->Unit(benchmark::kSecond);

void BM_QuasiStaticImage(benchmark::State& state) {
  const ti::OrbitMap map = bench_map();
  const afmkit::scan::Grid g{512, 512, 1e-6, 1e-6, -0.5e-6, -0.5e-6};
  const afmkit::scan::Surface surface(afmkit::scan::particles(g, {12, 5e-9, 1}), afmkit::scan::Tilt(0.0, 0.0));
  ti::RasterSpec raster;  // 256 × 256 over 1 µm
  raster.tip_speed = 2.0 * raster.width * 1.0;  // line rate 1 Hz
  ti::FeedbackSpec feedback;
  for (auto _ : state) {
    ti::QuasiStaticEngine engine(map, kCantilever.scales(), 2.0 * 100.0 / (2.0 * 3.141592653589793 * 300e3),
                                 feedback.lockin_bandwidth);
    const auto t = std::chrono::steady_clock::now();
    const ti::ImagingResult r = ti::scan_image(engine, surface, raster, feedback);
    benchmark::DoNotOptimize(r);
    state.counters["seconds"] = seconds_since(t);
    state.counters["ns_per_update"] = 1e9 * seconds_since(t) / static_cast<double>(r.updates);
    std::printf("quasi-static image 256 x 256 (trace + retrace, %ld updates): %.3f s\n", r.updates, seconds_since(t));
  }
}
BENCHMARK(BM_QuasiStaticImage)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
