#include "file_bytes.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::scan::detail {

std::string read_file_bytes(const std::string& path, std::string_view format, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw InputError(fmt::format("cannot read {} file '{}': no such file", format, path));
  if (!fs::is_regular_file(st))
    throw InputError(fmt::format("{} file '{}' is not a regular file (a directory, FIFO or device)", format, path));
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw InputError(fmt::format("cannot read {} file '{}': {}", format, path, ec.message()));
  if (size > max_bytes)
    throw InputError(fmt::format("{} file '{}' has {} bytes, more than the {} bytes allowed", format, path, size,
                                 max_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot open {} file '{}'", format, path));
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw InputError(fmt::format("cannot read {} file '{}'", format, path));
  return std::move(bytes).str();
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
