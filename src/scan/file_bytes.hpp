#pragma once
// Internal helpers of the scan file formats (not installed): reading a whole file, quoting text in messages,
// little-endian numbers, checking a text field that goes into a header line.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace afmkit::scan::detail {

/// The bytes of the regular file at `path`. InputError naming `format` and the path when it does not exist, is not
/// a regular file, cannot be read or is larger than `max_bytes`.
std::string read_file_bytes(const std::string& path, std::string_view format, std::uintmax_t max_bytes);

/// `text` for a message: quoted, at most 40 bytes, control bytes and bytes >= 0x80 written as \xNN.
std::string shown(std::string_view text);

/// Throws InvalidParameter(name) unless `text` has no control character (< 0x20, 0x7F) and no leading or trailing
/// blank, so that it survives a `Key = Value` header line unchanged.
void check_header_text(const std::string& name, std::string_view text);

inline void append_le32(std::string& out, float value) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, 4);
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((bits >> (8 * k)) & 0xFFu));
}
inline void append_le64(std::string& out, double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, 8);
  for (int k = 0; k < 8; ++k) out.push_back(static_cast<char>((bits >> (8 * k)) & 0xFFu));
}
inline float load_le32(const char* p) {
  std::uint32_t bits = 0;
  for (int k = 0; k < 4; ++k) bits |= static_cast<std::uint32_t>(static_cast<unsigned char>(p[k])) << (8 * k);
  float value = 0;
  std::memcpy(&value, &bits, 4);
  return value;
}
inline double load_le64(const char* p) {
  std::uint64_t bits = 0;
  for (int k = 0; k < 8; ++k) bits |= static_cast<std::uint64_t>(static_cast<unsigned char>(p[k])) << (8 * k);
  double value = 0;
  std::memcpy(&value, &bits, 8);
  return value;
}

}  // namespace afmkit::scan::detail
