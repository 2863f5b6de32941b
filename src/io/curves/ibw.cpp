#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "binary_readers.hpp"

namespace afmkit::io::curves::detail {

std::vector<RawCurve> read_ibw(std::string_view, const std::string& origin, const ReadOptions&) {
  throw InputError(fmt::format("{}: the ibw reader is not in this build yet", origin));
}

}  // namespace afmkit::io::curves::detail
