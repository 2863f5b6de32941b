// Tail fit, noise estimate, isotonic fit and erfcx for the force reconstructions (reconstruct_kernels.hpp).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "afmkit/spectroscopy/reconstruct_kernels.hpp"

namespace afmkit::spectroscopy {

double erfcx(double x) {
  if (x < 25.0) return std::exp(x * x) * std::erfc(x);
  // asymptotic series (the terms shrink fast for x ≥ 25: the 4th is below 1e-9 of the first)
  const double r = 1.0 / (2.0 * x * x);
  return (1.0 - r + 3.0 * r * r - 15.0 * r * r * r) / (x * std::sqrt(std::numbers::pi));
}

ExponentialTail fit_exponential_tail(const std::vector<double>& t, const std::vector<double>& y) {
  ExponentialTail tail;
  const std::size_t n = t.size();
  if (n < 5 || n != y.size()) return tail;
  const std::size_t m = std::min(n, std::max<std::size_t>(5, n / 10));
  const double sign = y.back() > 0 ? 1.0 : -1.0;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = n - m; i < n; ++i) {
    if (!(sign * y[i] > 0)) return tail;
    const double x = t[i] - t.back(), v = std::log(sign * y[i]);
    sx += x, sy += v, sxx += x * x, sxy += x * v;
  }
  const double den = m * sxx - sx * sx;
  if (!(den > 0)) return tail;
  const double slope = (m * sxy - sx * sy) / den;
  if (!(slope < 0) || !std::isfinite(slope)) return tail;
  tail.active = true;
  tail.value = y.back();
  tail.decay_length = -1.0 / slope;
  return tail;
}

double estimate_noise(const std::vector<double>& y) {
  if (y.size() < 5) return 0.0;
  std::vector<double> d;
  d.reserve(y.size() - 2);
  for (std::size_t i = 1; i + 1 < y.size(); ++i) d.push_back(std::abs(y[i + 1] - 2.0 * y[i] + y[i - 1]));
  auto mid = d.begin() + static_cast<long>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  return 1.4826 * *mid / std::sqrt(6.0);
}

std::vector<double> isotonic_nonincreasing(const std::vector<double>& y) {
  // pool adjacent violators on blocks (mean, weight, length)
  struct Block {
    double mean, weight;
    std::size_t length;
  };
  std::vector<Block> blocks;
  for (double v : y) {
    blocks.push_back({v, 1.0, 1});
    while (blocks.size() > 1 && blocks[blocks.size() - 2].mean < blocks.back().mean) {
      Block b = blocks.back();
      blocks.pop_back();
      Block& a = blocks.back();
      a.mean = (a.mean * a.weight + b.mean * b.weight) / (a.weight + b.weight);
      a.weight += b.weight;
      a.length += b.length;
    }
  }
  std::vector<double> out;
  out.reserve(y.size());
  for (const Block& b : blocks) out.insert(out.end(), b.length, b.mean);
  return out;
}

}  // namespace afmkit::spectroscopy
