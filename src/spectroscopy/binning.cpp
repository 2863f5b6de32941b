#include "afmkit/spectroscopy/binning.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::spectroscopy {

BinnedBranch bin_branch(const std::vector<double>& distance, const std::vector<double>& force, double width) {
  if (!(width > 0) || !std::isfinite(width))
    throw InvalidParameter("bin_width", fmt::format("bin_width = {} m is out of range: must be > 0", width));
  BinnedBranch out;
  if (distance.empty()) return out;
  const auto [lo, hi] = std::minmax_element(distance.begin(), distance.end());
  const double first = std::floor(*lo / width + 0.5), last = std::floor(*hi / width + 0.5);
  if (last - first + 1 > 1e6)  // 40 bytes of sums per bin: at most 40 MB
    throw InvalidParameter("bin_width", fmt::format("bin_width = {:.4g} nm makes {:.3g} bins over the {:.4g} µm of "
                                                    "distances (at most 10^6): give a larger bin_width",
                                                    width * 1e9, last - first + 1, (*hi - *lo) * 1e6));
  const std::size_t bins = static_cast<std::size_t>(last - first) + 1;
  std::vector<double> sum(bins, 0.0), sum2(bins, 0.0), sumd(bins, 0.0);
  std::vector<std::size_t> count(bins, 0);
  // a per-bin shift (the first sample's force) keeps the variance accurate for forces far from 0
  std::vector<double> shift(bins, 0.0);
  for (std::size_t i = 0; i < distance.size(); ++i) {
    const std::size_t b = static_cast<std::size_t>(std::floor(distance[i] / width + 0.5) - first);
    if (count[b] == 0) shift[b] = force[i];
    const double v = force[i] - shift[b];
    sum[b] += v;
    sumd[b] += distance[i];
    sum2[b] += v * v;
    ++count[b];
  }
  for (std::size_t b = 0; b < bins; ++b) {
    if (count[b] == 0) continue;
    const double c = static_cast<double>(count[b]), mean = sum[b] / c;
    const double var = count[b] > 1 ? std::max(0.0, (sum2[b] - c * mean * mean) / (c - 1)) : 0.0;
    // the samples' mean distance, not the bin centre: a bin the samples cover only in part (at a branch's ends, at
    // a snap-in gap) keeps its mean force at the distance it belongs to (no bias of the end slopes)
    out.distance.push_back(std::clamp(sumd[b] / c, (first + static_cast<double>(b) - 0.5) * width,
                                      (first + static_cast<double>(b) + 0.5) * width));
    out.centre.push_back((first + static_cast<double>(b)) * width);
    out.force.push_back(shift[b] + mean);
    out.force_error.push_back(std::sqrt(var / c));
    out.count.push_back(count[b]);
  }
  return out;
}

}  // namespace afmkit::spectroscopy
