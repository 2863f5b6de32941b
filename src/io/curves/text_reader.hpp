#pragma once
// Text exports of force curves (docs/curve-files.md#text-exports): the generic delimited reader and its presets.
// Internal to the io_curves readers; read_curves.hpp is the interface.
#include <string>
#include <string_view>
#include <vector>

#include "afmkit/io/curves/read_curves.hpp"

namespace afmkit::io::curves::detail {

/// The text formats: "text" and the presets.
bool is_text_format(const std::string& format);

/// Reads a text export with `options.format` one of the text formats ("auto" is read as "text").
std::vector<RawCurve> read_text_curves(std::string_view bytes, const std::string& origin, const ReadOptions& options);

}  // namespace afmkit::io::curves::detail
