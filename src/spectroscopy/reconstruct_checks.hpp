#pragma once
// Input checks shared by the reconstructions (private to src/spectroscopy).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::spectroscopy::detail {

inline void require_finite(const char* key, const std::vector<double>& v) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw InvalidParameter(key, fmt::format("{}[{}] = {}: every value must be finite", key, i, v[i]));
}

/// The permutation that sorts `distance` ascending; InvalidParameter when it is not strictly monotone.
inline std::vector<std::size_t> monotone_order(const char* key, const std::vector<double>& distance) {
  const std::size_t n = distance.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (n >= 2 && distance[1] < distance[0]) std::reverse(order.begin(), order.end());
  for (std::size_t k = 1; k < n; ++k)
    if (!(distance[order[k]] > distance[order[k - 1]]))
      throw InvalidParameter(key, fmt::format("{} is not strictly monotone: {}[{}] = {} m after {}[{}] = {} m (a "
                                              "measured curve must be one sweep, in one direction)",
                                              key, key, order[k], distance[order[k]], key, order[k - 1],
                                              distance[order[k - 1]]));
  return order;
}

template <class T>
std::vector<T> permuted(const std::vector<T>& v, const std::vector<std::size_t>& order) {
  std::vector<T> out;
  out.reserve(order.size());
  for (std::size_t i : order) out.push_back(v[i]);
  return out;
}

}  // namespace afmkit::spectroscopy::detail
