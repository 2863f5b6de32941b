#include "afmkit/io/number_list.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/number.hpp"

namespace afmkit::io {

namespace {
bool separator(char c) { return c == ',' || c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
constexpr std::uintmax_t max_file_bytes = 64u << 20;
}  // namespace

std::vector<double> parse_number_list(std::string_view text, const std::string& origin) {
  std::vector<double> values;
  long line = 1;
  std::size_t i = 0;
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
        const std::string shown = word.size() > 40 ? std::string(word.substr(0, 40)) + "..." : std::string(word);
        throw InputError(fmt::format("{}:{}: '{}' is not a finite number", origin, line, shown));
      }
      values.push_back(*v);
      i = end;
    }
  }
  return values;
}

std::vector<double> read_number_list(const std::string& path, const std::string& parameter) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw InputError(fmt::format("{}: cannot read '{}': no such file", parameter, path));
  if (!fs::is_regular_file(st))
    throw InputError(fmt::format("{}: '{}' is not a regular file (a directory, FIFO or device)", parameter, path));
  if (fs::file_size(path, ec) > max_file_bytes)
    throw InputError(fmt::format("{}: '{}' is larger than 64 MiB: not a list of numbers", parameter, path));
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw InputError(fmt::format("{}: cannot read '{}'", parameter, path));
  return parse_number_list(text.str(), path);
}

}  // namespace afmkit::io
