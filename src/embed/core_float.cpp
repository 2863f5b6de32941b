// Internal: the float host build of the C core (afmkit_embed_core, compiled as C99). core_access.hpp.
#include <algorithm>
#include <cmath>
#include <vector>

#include "afmkit/embed/afmkit_embed.h"
#include "core_access.hpp"

#include "core_loop.inc"

namespace afmkit::embed::detail {
CoreSizes float_core_sizes() { return sizes(); }
double float_core_loop(const CoreArrays& a, const std::vector<double>& in, double gain,
                       const std::vector<double>& expected) {
  return loop(a, in, gain, expected);
}
}  // namespace afmkit::embed::detail
