#pragma once
// Stability charts of the seed-2 loop in the coupling plane (paper Figs. 2 and 4, any N and τ/T):
//  * exact boundary curves by D-subdivision: for fixed τ, Δ(iν; x, y) = E0(iν) + x E_x(iν) + y E_y(iν) is affine
//    in the couplings, so Δ(iν) = 0 is a real 2×2 linear system giving (x(ν), y(ν)) for each crossing frequency
//    ν > 0; ν = 0 gives the straight line Δ(0; x, y) = 0 (b = γΩ/K for one oscillator, α = 0 for couplings (20));
//  * a dense grid of the spectral abscissa (max Re s = −decay rate) by Newton tracking of the rightmost roots
//    with warm starts from the neighbouring grid point (OpenMP over rows);
//  * regions = connected sets of grid points with the same number of unstable roots, each labelled by an
//    argument-principle count at its most interior point (`mismatched_points` reports disagreements).
#include <functional>
#include <limits>
#include <vector>

#include "afmkit/control/loop_family.hpp"
#include "afmkit/core/cancellation.hpp"

namespace afmkit::control {

struct BoundaryPoint {
  double frequency;  ///< ν [rad/s] of the imaginary-axis root (0 for the s = 0 line)
  double x, y;
};
using BoundaryCurve = std::vector<BoundaryPoint>;

/// D-subdivision curves inside the window (polylines, split where they leave it). `max_frequency` NaN: from the
/// proven root-free bounds at the window corners (capped at 200 Ω, or (N + 20) Ω for a larger bank).
std::vector<BoundaryCurve> stability_boundaries(const LoopFamily& family, double x_min, double x_max, double y_min,
                                                double y_max,
                                                double max_frequency = std::numeric_limits<double>::quiet_NaN());

struct ChartSpec {
  LoopFamily family;
  double x_min = 0, x_max = 1, y_min = -1, y_max = 1;  ///< [rad/s]
  int x_points = 200, y_points = 200;                  ///< ≥ 2
  bool boundaries = true;
  bool certify_regions = true;
  int threads = 0;           ///< OpenMP threads (0: default)
  int tracked_roots = 16;    ///< roots tracked per grid point
  int seed_interval = 8;     ///< add the asymptotic seeds every this many grid points (1 = always)
  long max_recomputed_points = 2000;  ///< mismatched points recomputed with certified spectra (if not more)
  Cancellation cancellation;  ///< checked once per grid point (core/cancellation.hpp)
};

struct ChartRegion {
  int id = 0;
  int unstable_roots = 0;     ///< certified count (−1: infinitely many, neutral chain)
  int tracked_roots = 0;      ///< count from tracking
  long points = 0;
  double x = 0, y = 0;        ///< interior point used for the count
  bool certified = false;
};

struct StabilityChart {
  std::vector<double> x, y;           ///< grid coordinates
  std::vector<double> abscissa;       ///< spectral abscissa, row-major: [iy·nx + ix]
  std::vector<int> unstable_roots;    ///< per grid point (region label; −1: infinitely many)
  std::vector<int> region;            ///< region id per grid point
  std::vector<ChartRegion> regions;
  std::vector<BoundaryCurve> boundaries;
  long mismatched_points = 0;         ///< tracked count ≠ certified region count (not counted where every
                                      ///< tracked root is unstable and the region has more: a lower bound)
  long lower_bound_points = 0;        ///< every tracked root unstable and the region has more: the abscissa there
                                      ///< is the largest tracked real part (e.g. α < 0 at large N)
  long recomputed_points = 0;         ///< of those, abscissa recomputed (a fresh tracked spectrum; the certified
                                      ///< rightmost_roots() where that still disagrees)
  double at(int ix, int iy) const { return abscissa[static_cast<std::size_t>(iy) * x.size() + ix]; }
};

/// `progress(increment, total)` reports finished grid points; called from worker threads (must be
/// thread-safe); may be empty.
StabilityChart stability_chart(const ChartSpec& spec, const std::function<void(long, long)>& progress = {});

/// Delay-margin map τ_c(x, y) (the Fig. 4 contour data); +inf where no crossing, NaN where unstable at τ = 0.
struct MarginMap {
  std::vector<double> x, y;
  std::vector<double> critical_delay;      ///< row-major [iy·nx + ix]
  std::vector<double> crossing_frequency;
};
/// `cancellation` is checked once per grid point.
MarginMap delay_margin_map(const LoopFamily& family, double x_min, double x_max, int x_points, double y_min,
                           double y_max, int y_points, int threads = 0,
                           const std::function<void(long, long)>& progress = {},
                           const Cancellation& cancellation = {});

}  // namespace afmkit::control
