#include "file_bytes.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"

namespace afmkit::scan::detail {

std::string read_file_bytes(const std::string& path, std::string_view format, std::uintmax_t max_bytes) {
  return files::read_input_file(path, fmt::format("{} file", format), max_bytes);
}

std::string shown(std::string_view text) {
  constexpr std::size_t limit = 40;
  const bool cut = text.size() > limit;
  if (cut) text = text.substr(0, limit);
  std::string out = "'";
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c >= 0x7F)
      out += fmt::format("\\x{:02x}", c);
    else
      out += ch;
  }
  out += cut ? "...'" : "'";
  return out;
}

void check_header_text(const std::string& name, std::string_view text) {
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7F)
      throw InvalidParameter(name, fmt::format("{} = {} holds a control character (line break, tab, NUL, ...): "
                                               "it must fit on one header line",
                                               name, shown(text)));
  }
  if (!text.empty() && (text.front() == ' ' || text.back() == ' '))
    throw InvalidParameter(name, fmt::format("{} = {} starts or ends with a blank (a header reader would drop it)",
                                             name, shown(text)));
}

}  // namespace afmkit::scan::detail
