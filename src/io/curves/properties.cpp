#include "properties.hpp"

namespace afmkit::io::curves::detail {

namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\r'; }

std::string unescape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '\\' || i + 1 >= s.size()) {
      out += s[i];
      continue;
    }
    const char c = s[++i];
    out += c == 't' ? '\t' : c == 'n' ? '\n' : c == 'r' ? '\r' : c;
  }
  return out;
}

}  // namespace

Properties parse_properties(std::string_view text) {
  Properties props;
  std::size_t pos = 0;
  while (pos < text.size()) {
    // One logical line: physical lines joined where one ends with an odd number of backslashes.
    std::string logical;
    while (pos < text.size()) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string_view::npos) end = text.size();
      std::string_view line = text.substr(pos, end - pos);
      pos = end + 1;
      while (!line.empty() && blank(line.back())) line.remove_suffix(1);
      std::size_t start = 0;
      if (!logical.empty())
        while (start < line.size() && blank(line[start])) ++start;
      line.remove_prefix(start);
      std::size_t slashes = 0;
      while (slashes < line.size() && line[line.size() - 1 - slashes] == '\\') ++slashes;
      if (slashes % 2 == 1) {
        logical.append(line.substr(0, line.size() - 1));
        continue;
      }
      logical.append(line);
      break;
    }
    std::size_t i = 0;
    while (i < logical.size() && blank(logical[i])) ++i;
    if (i >= logical.size() || logical[i] == '#' || logical[i] == '!') continue;
    std::size_t k = i;
    while (k < logical.size() && logical[k] != '=' && logical[k] != ':' && !blank(logical[k])) {
      if (logical[k] == '\\') ++k;
      ++k;
    }
    const std::string key = unescape(std::string_view(logical).substr(i, std::min(k, logical.size()) - i));
    std::size_t v = k;
    while (v < logical.size() && blank(logical[v])) ++v;
    if (v < logical.size() && (logical[v] == '=' || logical[v] == ':')) ++v;
    while (v < logical.size() && blank(logical[v])) ++v;
    props[key] = v < logical.size() ? unescape(std::string_view(logical).substr(v)) : std::string();
  }
  return props;
}

}  // namespace afmkit::io::curves::detail
