#pragma once
// Internal (not installed): the part shared by the Gwyddion GSF and GXYZF readers — a magic line, `Key = Value`
// lines, NUL padding aligning the binary data to a multiple of 4 (GSF) or 8 (GXYZF).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace afmkit::scan::detail {

struct HeaderField {
  std::string key;
  std::string value;
  long line;  ///< 1 = the magic line
};

struct BinaryHeader {
  std::vector<HeaderField> fields;  ///< in file order, keys unique
  std::size_t header_end = 0;       ///< offset of the first NUL byte (end of the text header)
  std::size_t data_start = 0;       ///< first byte after the padding: a multiple of the alignment
  std::size_t nul_run = 0;          ///< number of consecutive NUL bytes from header_end (padding + data zeros)
  const HeaderField* find(std::string_view key) const;
};

/// Parses the magic line, the header lines and the padding of `bytes`. InputError "<origin>: …" on a missing
/// magic line, a header not ended by a NUL, padding bytes that are not NUL up to the next multiple of
/// `alignment`, a line that is not `Key = Value` or an empty key ("<origin>:<line>: …"), a duplicate key.
/// Whitespace around keys and values and at line ends (so a CR of a CR-LF line end) is dropped; blank lines are
/// skipped.
BinaryHeader parse_binary_header(std::string_view bytes, std::string_view magic, std::size_t alignment,
                                 std::string_view format, const std::string& origin);

/// The value of a positive integer field (digits only, in [1, max]); InputError naming the origin, the field and
/// its line when it is not, or when it is missing and `mandatory` (then 0 is returned when it is absent).
long header_count(const BinaryHeader& header, std::string_view key, long max, bool mandatory,
                  const std::string& origin);

/// The value of a text field ("" when absent); InputError naming the origin, the field and its line when it holds a
/// control character.
std::string header_text(const BinaryHeader& header, std::string_view key, const std::string& origin);

/// InputError for data of the wrong length after the header: names the counts, the bytes expected and found, and
/// says so when a run of NULs longer than the padding explains it (the padding must be 1 to `alignment` NULs).
[[noreturn]] void throw_size_mismatch(const BinaryHeader& header, std::size_t file_size, std::size_t alignment,
                                      const std::string& what, std::size_t value_bytes, const std::string& origin);

}  // namespace afmkit::scan::detail
