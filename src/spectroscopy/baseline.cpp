#include "afmkit/spectroscopy/baseline.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::spectroscopy {

BaselineFit fit_baseline(const ForceSegment& approach, double fraction, std::size_t min_points) {
  if (!(fraction > 0 && fraction <= 1))
    throw InvalidParameter("baseline_fraction", fmt::format("baseline_fraction = {} is out of range: must be in (0, 1]",
                                                            fraction));
  const auto [lo, hi] = std::minmax_element(approach.height.begin(), approach.height.end());
  BaselineFit fit;
  fit.height_to = *hi;
  fit.height_from = *hi - fraction * (*hi - *lo);
  // least squares on centred heights (well conditioned: z ~ 10 µm, range ~ 1 µm)
  const double zc = 0.5 * (fit.height_from + fit.height_to);
  double n = 0, sz = 0, sf = 0, szz = 0, szf = 0;
  for (std::size_t i = 0; i < approach.size(); ++i) {
    if (approach.height[i] < fit.height_from) continue;
    const double z = approach.height[i] - zc, f = approach.force[i];
    n += 1; sz += z; sf += f; szz += z * z; szf += z * f;
  }
  fit.points = static_cast<std::size_t>(n);
  if (fit.points < std::max<std::size_t>(min_points, 3) && fraction == 1)
    throw InvalidParameter("baseline_fraction",
                           fmt::format("baseline_fraction = 1: the whole approach holds {} samples, fewer than the {} a "
                                       "baseline fit needs (record a longer approach)",
                                       fit.points, std::max<std::size_t>(min_points, 3)));
  if (fit.points < std::max<std::size_t>(min_points, 3))
    throw InvalidParameter("baseline_fraction",
                           fmt::format("baseline_fraction = {}: the far {:.3g} % of the approach's height range ({:.4g} "
                                       "to {:.4g} µm) holds {} samples, fewer than the {} a baseline fit needs: give a "
                                       "larger baseline_fraction",
                                       fraction, 100 * fraction, fit.height_from * 1e6, fit.height_to * 1e6, fit.points,
                                       std::max<std::size_t>(min_points, 3)));
  const double det = n * szz - sz * sz;
  const double slope = det > 0 ? (n * szf - sz * sf) / det : 0.0;
  const double at_zc = (sf - slope * sz) / n;
  fit.slope = slope;
  fit.offset = at_zc - slope * zc;
  double ss = 0;
  for (std::size_t i = 0; i < approach.size(); ++i) {
    if (approach.height[i] < fit.height_from) continue;
    const double r = approach.force[i] - (at_zc + slope * (approach.height[i] - zc));
    ss += r * r;
  }
  fit.residual_rms = std::sqrt(ss / (n - 2));
  fit.mean_height = zc + sz / n;
  fit.level_error = fit.residual_rms / std::sqrt(n);
  const double sxx = szz - sz * sz / n;  // Σ(z − z̄)²
  fit.slope_error = sxx > 0 ? fit.residual_rms / std::sqrt(sxx) : 0.0;
  return fit;
}

void subtract_baseline(ForceSegment& segment, const BaselineFit& fit, double spring_constant) {
  for (std::size_t i = 0; i < segment.size(); ++i) {
    segment.force[i] -= fit.at(segment.height[i]);
    segment.deflection[i] = segment.force[i] / spring_constant;
  }
}

}  // namespace afmkit::spectroscopy
