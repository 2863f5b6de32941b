// Internal: the double host build of the C core. The same source (src/embed/c/afmkit_embed.c, written in the common
// subset of C99 and C++) compiled here in double with the symbol prefix afmkit_embed_hostd_, so that the host library
// does not depend on afmkit_embed_core_double (and never clashes with it when a program links both). core_access.hpp.
#include <algorithm>
#include <cmath>
#include <vector>

#define AFMKIT_EMBED_DOUBLE 1
#define AFMKIT_EMBED_NAME(x) afmkit_embed_hostd_##x
#include "c/afmkit_embed.c"
#include "core_access.hpp"

#include "core_loop.inc"

namespace afmkit::embed::detail {
CoreSizes double_core_sizes() { return sizes(); }
double double_core_loop(const CoreArrays& a, const std::vector<double>& in, double gain,
                        const std::vector<double>& expected) {
  return loop(a, in, gain, expected);
}
}  // namespace afmkit::embed::detail
