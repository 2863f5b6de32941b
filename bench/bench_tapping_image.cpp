// `afmkit tapping image` speed (issue 27 target: 256 × 256 pixels, trace and retrace, quasi-static engine ≤ 2 s).
// The case of the command's defaults: k = 40 N/m, f0 = 300 kHz, Q = 100, A0 = 20 nm, DMT + van der Waals
// (E* = 1 GPa, R = 10 nm, A_H = 6.4e-20 J), 12 particles of radius 5 nm on a 1 µm square (512² sample map), line rate
// 1 Hz, feedback at 50 kHz (97 updates per pixel: 12.7 million controller updates). Two parts, timed apart:
// BM_OrbitMap (the instrument sweep of 300 + 300 separations, once per run) and BM_QuasiStaticImage (the scan on
// that map). Each prints its wall time in seconds (counter "seconds").
// BM_TimeDomainVsQuasiStatic: the time-domain target (256 × 256 pixels, 20 drive cycles per pixel, DMT + vdW:
// <= 60 s on 2 cores) measured on 256 × 2 lines of the same raster (20 cycles per pixel, feedback at f0/5 = 60 kHz,
// 20480 cycles with trace and retrace; the cost of a cycle does not depend on the line), both engines on the same
// raster: microseconds per drive cycle, the ratio time-domain / quasi-static (wall and CPU time: the machine may be
// shared), and the extrapolation to 256 lines; Arg = −log10 of the cycles' tolerance (8: the engine's default).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>

#include "afmkit/impact/force_law.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "afmkit/tapping/image/quasi_static.hpp"
#include "afmkit/tapping/image/time_domain.hpp"
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

void BM_TimeDomainVsQuasiStatic(benchmark::State& state) {
  const ti::OrbitMap map = bench_map();
  const afmkit::scan::Grid g{512, 512, 1e-6, 1e-6, -0.5e-6, -0.5e-6};
  const afmkit::scan::Surface surface(afmkit::scan::particles(g, {12, 5e-9, 1}), afmkit::scan::Tilt(0.0, 0.0));
  const double f0 = 300e3, cycles_per_pixel = 20.0;
  ti::RasterSpec raster;  // 256 pixels × 2 lines of the 256 × 256 raster over 1 µm
  raster.lines = 2;
  raster.height = raster.width / 128.0;
  raster.tip_speed = raster.width / static_cast<double>(raster.pixels) / (cycles_per_pixel / f0);
  ti::FeedbackSpec feedback;
  feedback.update_rate = f0 / 5.0;
  for (auto _ : state) {
    ti::TimeDomainOptions o;
    o.lockin_bandwidth = feedback.lockin_bandwidth;
    // the cycles' relative tolerance 10^-arg (absolute: 1e-2 of it, in nm): 8 = the engine's default
    o.cycle_tolerance = std::pow(10.0, -static_cast<double>(state.range(0)));
    ti::TimeDomainEngine td(bench_model(), map, kCantilever.scales(), o);
    auto t = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();  // CPU time too: the machine is shared, the wall time is noisy
    const ti::ImagingResult r = ti::scan_image(td, surface, raster, feedback);
    const double td_seconds = seconds_since(t);
    const double td_cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    benchmark::DoNotOptimize(r);
    ti::QuasiStaticEngine qs(map, kCantilever.scales(), 2.0 * 100.0 / (2.0 * 3.141592653589793 * f0),
                             feedback.lockin_bandwidth);
    t = std::chrono::steady_clock::now();
    const std::clock_t q0 = std::clock();
    const ti::ImagingResult q = ti::scan_image(qs, surface, raster, feedback);
    const double qs_seconds = seconds_since(t);
    const double qs_cpu = static_cast<double>(std::clock() - q0) / CLOCKS_PER_SEC;
    benchmark::DoNotOptimize(q);
    const double us_per_cycle = 1e6 * td_seconds / static_cast<double>(td.cycles());
    const double full = 2.0 * 256.0 * 256.0 * cycles_per_pixel * us_per_cycle * 1e-6;
    state.counters["td_seconds"] = td_seconds;
    state.counters["qs_seconds"] = qs_seconds;
    state.counters["us_per_cycle"] = us_per_cycle;
    state.counters["cpu_us_per_cycle"] = 1e6 * td_cpu / static_cast<double>(td.cycles());
    state.counters["ratio_td_qs"] = td_seconds / qs_seconds;
    state.counters["steps_per_cycle"] = static_cast<double>(td.steps()) / static_cast<double>(td.cycles());
    state.counters["extrapolated_256x256_s"] = full;
    std::printf("relative tolerance 1e-%ld: time-domain %ld cycles (%ld events, %.1f integrator steps a cycle): %.3f s, %.1f us a cycle; "
                "quasi-static on the same raster %.4f s; ratio %.0f; 256 x 256 x 20 cycles, trace + retrace "
                "(2.6e6 cycles): %.0f s on one core\n",
                static_cast<long>(state.range(0)), td.cycles(), td.events(), static_cast<double>(td.steps()) / static_cast<double>(td.cycles()),
                td_seconds, us_per_cycle, qs_seconds, td_seconds / qs_seconds, full);
    std::printf("  (CPU time %.3f s: %.1f us a cycle; quasi-static %.4f s; CPU ratio %.0f; 256 x 256 x 20 cycles, "
                "trace + retrace: %.0f s of CPU, one core)\n",
                td_cpu, 1e6 * td_cpu / static_cast<double>(td.cycles()), qs_cpu, td_cpu / qs_cpu,
                2.0 * 256.0 * 256.0 * cycles_per_pixel * td_cpu / static_cast<double>(td.cycles()));
    state.counters["ratio_td_qs_cpu"] = td_cpu / qs_cpu;
  }
}
BENCHMARK(BM_TimeDomainVsQuasiStatic)->Arg(8)->Arg(10)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
