#include "binary_header.hpp"

#include <charconv>
#include <system_error>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "file_bytes.hpp"

namespace afmkit::scan::detail {

namespace {
bool blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
std::string_view strip(std::string_view s) {
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}
}  // namespace

const HeaderField* BinaryHeader::find(std::string_view key) const {
  for (const HeaderField& f : fields)
    if (f.key == key) return &f;
  return nullptr;
}

BinaryHeader parse_binary_header(std::string_view bytes, std::string_view magic, std::size_t alignment,
                                 std::string_view format, const std::string& origin) {
  if (bytes.substr(0, magic.size()) != magic)
    throw InputError(fmt::format("{}: not a {} file: it does not start with the line '{}'", origin, format,
                                 magic.substr(0, magic.size() - 1)));
  BinaryHeader h;
  const std::size_t nul = bytes.find('\0', magic.size());
  if (nul == std::string_view::npos)
    throw InputError(fmt::format("{}: bad padding: no NUL byte ends the text header (it must end with 1 to {} NUL "
                                 "bytes so that the data starts at a multiple of {})",
                                 origin, alignment, alignment));
  h.header_end = nul;
  h.data_start = nul + alignment - nul % alignment;
  for (std::size_t k = nul; k < h.data_start; ++k) {
    if (k >= bytes.size())
      throw InputError(fmt::format("{}: bad padding: the file ends at byte {}, inside the NUL padding that must run "
                                   "to byte {} (a multiple of {})",
                                   origin, bytes.size(), h.data_start, alignment));
    if (bytes[k] != '\0')
      throw InputError(fmt::format("{}: bad padding: byte {} is 0x{:02x}, not NUL: the header (ending at byte {}) "
                                   "must be followed by NULs up to byte {}, a multiple of {}",
                                   origin, k, static_cast<unsigned char>(bytes[k]), nul, h.data_start, alignment));
  }
  h.nul_run = 0;
  while (nul + h.nul_run < bytes.size() && bytes[nul + h.nul_run] == '\0') ++h.nul_run;

  const std::string_view text = bytes.substr(magic.size(), nul - magic.size());
  long line = 1;
  std::size_t start = 0;
  while (start < text.size()) {
    ++line;
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view raw = strip(text.substr(start, end - start));
    start = end + 1;
    if (raw.empty()) continue;
    const std::size_t eq = raw.find('=');
    if (eq == std::string_view::npos)
      throw InputError(fmt::format("{}:{}: header line {} is not 'Key = Value'", origin, line, shown(raw)));
    const std::string_view key = strip(raw.substr(0, eq));
    if (key.empty()) throw InputError(fmt::format("{}:{}: header line {} has no key", origin, line, shown(raw)));
    if (const HeaderField* first = h.find(key))
      throw InputError(fmt::format("{}:{}: duplicate header field {} (first on line {})", origin, line, shown(key),
                                   first->line));
    h.fields.push_back({std::string(key), std::string(strip(raw.substr(eq + 1))), line});
  }
  return h;
}

long header_count(const BinaryHeader& header, std::string_view key, long max, bool mandatory,
                  const std::string& origin) {
  const HeaderField* f = header.find(key);
  if (!f) {
    if (mandatory) throw InputError(fmt::format("{}: missing mandatory header field {}", origin, key));
    return 0;
  }
  long value = 0;
  const std::string_view v = f->value;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
  const bool digits = !v.empty() && v.front() >= '0' && v.front() <= '9';
  if (!digits || ec != std::errc() || end != v.data() + v.size() || value < 1 || value > max)
    throw InputError(fmt::format("{}:{}: {} = {} is not a positive integer in [1, {}]", origin, f->line, key,
                                 shown(v), max));
  return value;
}

void throw_size_mismatch(const BinaryHeader& header, std::size_t file_size, std::size_t alignment,
                         const std::string& what, std::size_t value_bytes, const std::string& origin) {
  const std::size_t found = file_size - header.data_start;
  const std::size_t padding = header.data_start - header.header_end;
  if (header.nul_run > padding && header.header_end + header.nul_run <= file_size &&
      header.nul_run - padding <= found && found - (header.nul_run - padding) == value_bytes)
    throw InputError(fmt::format("{}: bad padding: {} NUL bytes follow the header (ending at byte {}); the padding "
                                 "must be 1 to {} NULs ending at a multiple of {}",
                                 origin, header.nul_run, header.header_end, alignment, alignment));
  throw InputError(fmt::format("{}: size mismatch: {} need {} bytes after the header (from byte {}), the file has {}"
                               " ({})",
                               origin, what, value_bytes, header.data_start, found,
                               found < value_bytes ? "truncated" : "too long"));
}

std::string header_text(const BinaryHeader& header, std::string_view key, const std::string& origin) {
  const HeaderField* f = header.find(key);
  if (!f) return "";
  for (char ch : f->value) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7F)
      throw InputError(fmt::format("{}:{}: {} = {} holds a control character", origin, f->line, key, shown(f->value)));
  }
  return f->value;
}

}  // namespace afmkit::scan::detail
