#pragma once
// Java properties text (JPK .jpk-force headers): "key=value" lines, '#' and '!' comments, backslash escapes and
// continuation lines. Internal to io_curves.
#include <map>
#include <string>
#include <string_view>

namespace afmkit::io::curves::detail {

using Properties = std::map<std::string, std::string, std::less<>>;

/// The properties of `text` (later keys win).
Properties parse_properties(std::string_view text);

}  // namespace afmkit::io::curves::detail
