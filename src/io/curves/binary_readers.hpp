#pragma once
// The native binary readers (docs/curve-files.md): JPK .jpk-force (zip archive) and Asylum .ibw (Igor binary
// wave). Internal to io_curves; read_curves.hpp is the interface.
#include <string>
#include <string_view>
#include <vector>

#include "afmkit/io/curves/read_curves.hpp"

namespace afmkit::io::curves::detail {

/// Every curve of a JPK .jpk-force archive (one curve; a force map holds several).
std::vector<RawCurve> read_jpk_force(std::string_view bytes, const std::string& origin, const ReadOptions& options);

/// The curve of an Asylum Research .ibw force curve (Igor binary wave version 5 or 2).
std::vector<RawCurve> read_ibw(std::string_view bytes, const std::string& origin, const ReadOptions& options);

}  // namespace afmkit::io::curves::detail
