#include "afmkit/io/number_list.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"
#include "afmkit/io/number.hpp"

namespace afmkit::io {

namespace {
bool separator(char c) { return c == ',' || c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
constexpr std::uintmax_t max_file_bytes = 64u << 20;

/// A word of the file for a message: at most 40 bytes, a byte-order mark spelled out, other control and non-ASCII
/// bytes as \xNN, so that nothing invisible or terminal-changing reaches the message.
std::string shown(std::string_view word) {
  const bool cut = word.size() > 40;
  if (cut) word = word.substr(0, 40);
  std::string out;
  for (std::size_t i = 0; i < word.size(); ++i) {
    const auto c = static_cast<unsigned char>(word[i]);
    if (word.substr(i, 3) == "\xEF\xBB\xBF") {
      out += "<U+FEFF byte-order mark>";
      i += 2;
    } else if (c < 0x20 || c >= 0x7F) {
      out += fmt::format("\\x{:02x}", c);
    } else {
      out += word[i];
    }
  }
  return cut ? out + "..." : out;
}
}  // namespace

std::vector<double> parse_number_list(std::string_view text, const std::string& origin) {
  std::vector<double> values;
  long line = 1;
  std::size_t i = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;  // a byte-order mark at the start (spreadsheets)
  while (i < text.size()) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (separator(c)) {
      ++i;
    } else if (c == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else {
      std::size_t end = i;
      while (end < text.size() && !separator(text[end]) && text[end] != '#') ++end;
      const std::string_view word = text.substr(i, end - i);
      const auto v = parse_real(word);
      if (!v || !std::isfinite(*v)) {
        throw InputError(fmt::format("{}:{}: '{}' is not a finite number", origin, line, shown(word)));
      }
      values.push_back(*v);
      i = end;
    }
  }
  return values;
}

std::vector<double> read_number_list(const std::string& path, const std::string& parameter) {
  return parse_number_list(files::read_input_file(path, parameter, max_file_bytes), path);
}

}  // namespace afmkit::io
