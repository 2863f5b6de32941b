#pragma once
// A minimal Igor binary wave version 5 writer for the tests: a 2-D float32 wave (points x channels) with column
// labels, a note and a valid header checksum, laid out as the reader's header comment describes.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace curves_test {

inline void put(std::string& b, std::size_t at, const void* v, std::size_t n) { std::memcpy(&b[at], v, n); }

inline std::string make_ibw(const std::vector<std::string>& labels, const std::vector<std::vector<float>>& columns,
                            const std::string& note, const char* units = "m") {
  const std::int32_t rows = columns.empty() ? 0 : static_cast<std::int32_t>(columns[0].size());
  const auto cols = static_cast<std::int32_t>(columns.size());
  const std::int32_t data_bytes = rows * cols * 4;
  const std::int32_t labels_bytes = (cols + 1) * 32;
  std::string b(64 + 320 + static_cast<std::size_t>(data_bytes), '\0');
  const std::int16_t version = 5;
  put(b, 0, &version, 2);
  const std::int32_t wfm = 320 + data_bytes, zero = 0, note_size = static_cast<std::int32_t>(note.size());
  put(b, 4, &wfm, 4);
  put(b, 8, &zero, 4);
  put(b, 12, &note_size, 4);
  put(b, 40, &labels_bytes, 4);  // dimLabelsSize[1]
  const std::int32_t npnts = rows * cols;
  put(b, 64 + 12, &npnts, 4);
  const std::int16_t type = 2;  // float32
  put(b, 64 + 16, &type, 2);
  std::memcpy(&b[64 + 28], "test", 4);
  put(b, 64 + 68, &rows, 4);
  put(b, 64 + 72, &cols, 4);
  const double dt = 1e-3;
  put(b, 64 + 84, &dt, 8);
  std::memcpy(&b[64 + 148], units, std::strlen(units));
  b[64 + 152] = 's';
  for (std::int32_t j = 0; j < cols; ++j)
    for (std::int32_t i = 0; i < rows; ++i) put(b, 384 + 4 * static_cast<std::size_t>(j * rows + i), &columns[j][i], 4);
  std::uint16_t sum = 0;
  for (std::size_t i = 0; i < 384; i += 2) {
    std::uint16_t v;
    std::memcpy(&v, &b[i], 2);
    sum = static_cast<std::uint16_t>(sum + v);
  }
  const auto check = static_cast<std::uint16_t>(-sum);
  put(b, 2, &check, 2);
  b += note;
  std::string lab(static_cast<std::size_t>(labels_bytes), '\0');
  for (std::size_t j = 0; j < labels.size(); ++j) std::memcpy(&lab[(j + 1) * 32], labels[j].data(), labels[j].size());
  b += lab;
  return b;
}

}  // namespace curves_test
