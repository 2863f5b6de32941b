// Spectral-abscissa chart with warm-started root tracking and certified region labels (stability_chart.hpp).
#include "afmkit/control/stability_chart.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <queue>

#include <omp.h>

#include "afmkit/control/delay_margin.hpp"
#include "afmkit/control/spectrum.hpp"
#include "afmkit/core/parallel.hpp"
#include "afmkit/core/computed.hpp"
#include "afmkit/core/validate.hpp"
#include "spectra_detail.hpp"
#include "tracking.hpp"

namespace afmkit::control {

using spectra_detail::RootTracker;
using spectra_detail::TrackedSpectrum;

namespace {
std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) v[i] = n == 1 ? a : a + (b - a) * i / (n - 1);
  return v;
}

void check_spec(const ChartSpec& s) {
  spectra_detail::validate_window(s.x_min, s.x_max, s.y_min, s.y_max);
  validate::in_range("x_points", static_cast<long>(s.x_points), 2L, 100000L);
  validate::in_range("y_points", static_cast<long>(s.y_points), 2L, 100000L);
  validate::in_range("threads", static_cast<long>(s.threads), 0L, 1024L);
  validate::in_range("tracked_roots", static_cast<long>(s.tracked_roots), 1L, 1000L);
  validate::in_range("seed_interval", static_cast<long>(s.seed_interval), 1L, 1000000L);
  validate::in_range("max_recomputed_points", s.max_recomputed_points, 0L, 1000000000L);
}

// Runs body(i) for i in [0, n) on `threads` OpenMP threads; rethrows the first exception.
template <class F>
void parallel_for(long n, int threads, F&& body) {
  ExceptionCollector errors;
  const int nt = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
  for (long i = 0; i < n; ++i) errors.run([&] { body(i); });
  errors.rethrow();
}

// Connected components of equal tracked counts; each labelled by a certified count at its most interior point.
// `saturated`: the tracked count is only a lower bound there (every tracked root unstable).
void label_regions(const ChartSpec& spec, const RootTracker& tracker, StabilityChart& c,
                   const std::vector<int>& tracked, const std::vector<char>& saturated) {
  const int nx = spec.x_points, ny = spec.y_points;
  c.region.assign(static_cast<std::size_t>(nx) * ny, -1);
  const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
  int next = 0;
  std::vector<int> dist(c.region.size(), -1);
  for (int start = 0; start < nx * ny; ++start) {
    if (c.region[start] >= 0) continue;
    const int id = next++;
    std::vector<int> members{start};
    c.region[start] = id;
    for (std::size_t q = 0; q < members.size(); ++q) {
      const int p = members[q], px = p % nx, py = p / nx;
      for (int k = 0; k < 4; ++k) {
        const int qx = px + dx[k], qy = py + dy[k];
        if (qx < 0 || qy < 0 || qx >= nx || qy >= ny) continue;
        const int n = qy * nx + qx;
        if (c.region[n] < 0 && tracked[n] == tracked[start]) {
          c.region[n] = id;
          members.push_back(n);
        }
      }
    }
    // distance transform inside the component (BFS from its border)
    std::queue<int> bfs;
    for (int p : members) {
      const int px = p % nx, py = p / nx;
      bool border = false;
      for (int k = 0; k < 4; ++k) {
        const int qx = px + dx[k], qy = py + dy[k];
        if (qx < 0 || qy < 0 || qx >= nx || qy >= ny || c.region[qy * nx + qx] != id) border = true;
      }
      dist[p] = border ? 0 : -1;
      if (border) bfs.push(p);
    }
    int best = members.front();
    while (!bfs.empty()) {
      const int p = bfs.front();
      bfs.pop();
      if (dist[p] > dist[best]) best = p;
      const int px = p % nx, py = p / nx;
      for (int k = 0; k < 4; ++k) {
        const int qx = px + dx[k], qy = py + dy[k];
        if (qx < 0 || qy < 0 || qx >= nx || qy >= ny) continue;
        const int n = qy * nx + qx;
        if (c.region[n] == id && dist[n] < 0) {
          dist[n] = dist[p] + 1;
          bfs.push(n);
        }
      }
    }
    ChartRegion r;
    r.id = id;
    r.tracked_roots = tracked[start];
    r.unstable_roots = tracked[start];
    r.points = static_cast<long>(members.size());
    r.x = c.x[best % nx];
    r.y = c.y[best / nx];
    c.regions.push_back(r);
  }
  if (spec.certify_regions) {
    parallel_for(static_cast<long>(c.regions.size()), spec.threads, [&](long i) {
      ChartRegion& r = c.regions[i];
      if (r.tracked_roots < 0) {  // neutral chain in Re s ≥ 0: proven by the formula of the bound
        r.certified = true;
        return;
      }
      spec.cancellation.check();
      const UnstableCount u = unstable_roots(spec.family.at(r.x, r.y));
      r.unstable_roots = u.count;
      r.certified = !u.marginal;
    });
  }
  c.unstable_roots.assign(c.region.size(), 0);
  std::vector<long> redo;
  for (std::size_t p = 0; p < c.region.size(); ++p) {
    const ChartRegion& r = c.regions[c.region[p]];
    c.unstable_roots[p] = r.unstable_roots;
    const bool lower_bound = saturated[p] && r.unstable_roots > tracked[p];
    if (lower_bound) ++c.lower_bound_points;
    if (r.unstable_roots != tracked[p] && !lower_bound) {
      ++c.mismatched_points;
      redo.push_back(static_cast<long>(p));
    }
  }
  // tracking lost roots there: a fresh tracked spectrum (delay-free poles continued, O(N²) with a small constant)
  // merged with the point's abscissa; if its count still disagrees, the certified spectrum (bounded effort)
  if (static_cast<long>(redo.size()) <= spec.max_recomputed_points) {
    parallel_for(static_cast<long>(redo.size()), spec.threads, [&](long i) {
      spec.cancellation.check();
      const long p = redo[i];
      const LoopSpec loop = spec.family.at(c.x[p % nx], c.y[p / nx]);
      const TrackedSpectrum fresh = tracker.initial(loop);
      const int region_count = c.unstable_roots[p];
      const bool agrees = fresh.unstable() == region_count ||
                          (fresh.saturated(tracker.keep()) && region_count > fresh.unstable());
      c.abscissa[p] = agrees ? std::max(c.abscissa[p], fresh.abscissa()) : rightmost_roots(loop).spectral_abscissa;
    });
    c.recomputed_points = static_cast<long>(redo.size());
  }
}
}  // namespace

namespace {
// stability_chart on checked arguments (the public function checks them first)
StabilityChart stability_chart_checked(const ChartSpec& spec, const std::function<void(long, long)>& progress) {
  const int nx = spec.x_points, ny = spec.y_points;
  StabilityChart c;
  c.x = linspace(spec.x_min, spec.x_max, nx);
  c.y = linspace(spec.y_min, spec.y_max, ny);
  c.abscissa.assign(static_cast<std::size_t>(nx) * ny, 0.0);
  std::vector<int> tracked(c.abscissa.size(), 0);
  std::vector<char> saturated(c.abscissa.size(), 0);
  const RootTracker tracker(spec.tracked_roots);
  const long total = static_cast<long>(nx) * ny;

  // column 0, marching in y (fresh initialisation every 16 rows merged in)
  std::vector<TrackedSpectrum> row_start(ny);
  TrackedSpectrum cur = tracker.initial(spec.family.at(c.x[0], c.y[0]));
  for (int j = 0; j < ny; ++j) {
    spec.cancellation.check();
    const LoopSpec loop = spec.family.at(c.x[0], c.y[j]);
    cur = tracker.update(loop, cur, true);
    if (j % 16 == 15) cur = tracker.merge(cur, tracker.initial(loop));
    row_start[j] = cur;
  }
  // rows in parallel, warm starts along x
  parallel_for(ny, spec.threads, [&](long j) {
    TrackedSpectrum s = row_start[j];
    for (int i = 0; i < nx; ++i) {
      spec.cancellation.check();
      if (i > 0) s = tracker.update(spec.family.at(c.x[i], c.y[j]), s, i % spec.seed_interval == 0);
      const std::size_t p = static_cast<std::size_t>(j) * nx + i;
      c.abscissa[p] = s.abscissa();
      tracked[p] = s.unstable();
      saturated[p] = s.saturated(tracker.keep()) ? 1 : 0;
    }
    if (progress) progress(static_cast<long>(nx), total);
  });
  label_regions(spec, tracker, c, tracked, saturated);
  if (spec.boundaries) c.boundaries = stability_boundaries(spec.family, spec.x_min, spec.x_max, spec.y_min, spec.y_max);
  return c;
}
}  // namespace

StabilityChart stability_chart(const ChartSpec& spec, const std::function<void(long, long)>& progress) {
  check_spec(spec);
  // the arguments are checked: what is refused from here on was computed (core/computed.hpp)
  return computed("stability chart", [&] { return stability_chart_checked(spec, progress); });
}

namespace {
// delay_margin_map on checked arguments (the public function checks them first)
MarginMap delay_margin_map_checked(const LoopFamily& family, double x_min, double x_max, int x_points, double y_min,
                                   double y_max, int y_points, int threads,
                                   const std::function<void(long, long)>& progress, const Cancellation& cancellation) {
  MarginMap m;
  m.x = linspace(x_min, x_max, x_points);
  m.y = linspace(y_min, y_max, y_points);
  const std::size_t n = static_cast<std::size_t>(x_points) * y_points;
  m.critical_delay.assign(n, 0.0);
  m.crossing_frequency.assign(n, 0.0);
  parallel_for(static_cast<long>(n), threads, [&](long p) {
    cancellation.check();
    const int i = static_cast<int>(p % x_points), j = static_cast<int>(p / x_points);
    const DelayMargin dm = delay_margin(family.at(m.x[i], m.y[j]));
    m.critical_delay[p] = dm.stable_at_reference ? dm.upper : std::numeric_limits<double>::quiet_NaN();
    m.crossing_frequency[p] = dm.upper_frequency;
    if (progress) progress(1, static_cast<long>(n));
  });
  return m;
}
}  // namespace

MarginMap delay_margin_map(const LoopFamily& family, double x_min, double x_max, int x_points, double y_min,
                           double y_max, int y_points, int threads, const std::function<void(long, long)>& progress,
                           const Cancellation& cancellation) {
  spectra_detail::validate_window(x_min, x_max, y_min, y_max);
  validate::in_range("x_points", static_cast<long>(x_points), 2L, 100000L);
  validate::in_range("y_points", static_cast<long>(y_points), 2L, 100000L);
  // the arguments are checked: what is refused from here on was computed (core/computed.hpp)
  return computed("delay-margin map", [&] {
    return delay_margin_map_checked(family, x_min, x_max, x_points, y_min, y_max, y_points, threads, progress,
                                    cancellation);
  });
}

}  // namespace afmkit::control
