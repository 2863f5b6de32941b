// Asylum Research force curves as Igor binary waves, version 5 (docs/curve-files.md#asylum-ibw): a 64-byte
// BinHeader5, a 320-byte WaveHeader5 (dimensions, scaling, units), the data (column-major, one column per channel
// of a 2-D wave), then the formula, the note ("Key: value" lines separated by CR), the extended units and the
// dimension labels (32 bytes each; the labels of dimension 1 name the columns: "Raw", "Defl", "ZSnsr", ...).
// Asylum's ZSnsr grows towards the sample: height = -ZSnsr. The note's "Indexes: 0,1008,2015" and
// "Direction: NaN,1,-1" split the curve into segments (1: extend, -1: retract, 0: dwell).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "binary_readers.hpp"

namespace afmkit::io::curves::detail {

namespace {

constexpr std::size_t kBinHeader = 64;
constexpr std::size_t kWaveHeader = 320;

class Bytes {
 public:
  Bytes(std::string_view b, bool little) : b_(b), little_(little) {}
  std::uint64_t u(std::size_t at, int width) const {
    std::uint64_t v = 0;
    for (int i = 0; i < width; ++i) {
      const auto byte = static_cast<unsigned char>(b_[at + static_cast<std::size_t>(little_ ? width - 1 - i : i)]);
      v = (v << 8) | byte;
    }
    return v;
  }
  std::int32_t i32(std::size_t at) const { return static_cast<std::int32_t>(static_cast<std::uint32_t>(u(at, 4))); }
  std::int16_t i16(std::size_t at) const { return static_cast<std::int16_t>(static_cast<std::uint16_t>(u(at, 2))); }
  double f64(std::size_t at) const {
    const std::uint64_t v = u(at, 8);
    double d;
    std::memcpy(&d, &v, 8);
    return d;
  }
  float f32(std::size_t at) const {
    const auto v = static_cast<std::uint32_t>(u(at, 4));
    float f;
    std::memcpy(&f, &v, 4);
    return f;
  }

 private:
  std::string_view b_;
  bool little_;
};

std::string c_string(std::string_view field) {
  const auto nul = field.find('\0');
  return std::string(field.substr(0, nul));
}

std::optional<double> note_number(std::string_view note, std::string_view key) {
  std::size_t pos = 0;
  while (pos < note.size()) {
    std::size_t end = note.find_first_of("\r\n", pos);
    if (end == std::string_view::npos) end = note.size();
    const std::string_view line = note.substr(pos, end - pos);
    pos = end + 1;
    if (line.size() > key.size() && line.compare(0, key.size(), key) == 0 && line[key.size()] == ':') {
      const std::string value(line.substr(key.size() + 1));
      char* stop = nullptr;
      const double v = std::strtod(value.c_str(), &stop);
      if (stop == value.c_str()) return std::nullopt;
      while (*stop == ' ' || *stop == '\t') ++stop;
      if (*stop != '\0' || !std::isfinite(v)) return std::nullopt;
      return v;
    }
  }
  return std::nullopt;
}

std::optional<std::string> note_text(std::string_view note, std::string_view key) {
  std::size_t pos = 0;
  while (pos < note.size()) {
    std::size_t end = note.find_first_of("\r\n", pos);
    if (end == std::string_view::npos) end = note.size();
    const std::string_view line = note.substr(pos, end - pos);
    pos = end + 1;
    if (line.size() > key.size() && line.compare(0, key.size(), key) == 0 && line[key.size()] == ':')
      return std::string(line.substr(key.size() + 1));
  }
  return std::nullopt;
}

// "0,1008,2015" -> numbers (NaN for "NaN"); nullopt when a field is not a number.
std::optional<std::vector<double>> number_list(const std::string& text) {
  std::vector<double> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t end = text.find(',', pos);
    if (end == std::string::npos) end = text.size();
    std::string field = text.substr(pos, end - pos);
    field.erase(0, field.find_first_not_of(' '));
    field.erase(field.find_last_not_of(' ') + 1);  // npos + 1 == 0: all blanks
    pos = end + 1;
    if (field.empty()) {
      if (end == text.size()) break;  // trailing comma
      return std::nullopt;
    }
    char* stop = nullptr;
    const double v = std::strtod(field.c_str(), &stop);
    if (*stop != '\0') return std::nullopt;
    out.push_back(v);
    if (end == text.size()) break;
  }
  return out;
}

bool same_name(std::string a, std::string b) {
  for (char& c : a) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (char& c : b) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return a == b;
}

}  // namespace

std::vector<RawCurve> read_ibw(std::string_view bytes, const std::string& origin, const ReadOptions& options) {
  if (bytes.size() < 2)
    throw InputError(fmt::format("{}: {} bytes: not an Igor binary wave (too short for its version field)", origin,
                                 bytes.size()));
  const Bytes le(bytes, true), be(bytes, false);
  const bool little = le.i16(0) == 5 || le.i16(0) == 2;
  const Bytes& b = little ? le : be;
  const int version = b.i16(0);
  if (version == 2)
    throw InputError(fmt::format("{}: Igor binary wave version 2: a 1-D wave of one channel cannot hold a force "
                                 "curve; save the curve as a version 5 wave (Asylum's .ibw)",
                                 origin));
  if (version != 5)
    throw InputError(fmt::format("{}: byte 0: version field {} (or {} big-endian): not an Igor binary wave of "
                                 "version 5",
                                 origin, le.i16(0), be.i16(0)));
  if (bytes.size() < kBinHeader + kWaveHeader)
    throw InputError(fmt::format("{}: truncated: {} bytes, the headers of a version 5 wave take {}", origin,
                                 bytes.size(), kBinHeader + kWaveHeader));
  std::uint16_t sum = 0;
  for (std::size_t i = 0; i < kBinHeader + kWaveHeader; i += 2) sum = static_cast<std::uint16_t>(sum + b.u(i, 2));
  if (sum != 0)
    throw InputError(fmt::format("{}: bytes 0-383: header checksum mismatch (corrupt or not an Igor wave)", origin));
  // BinHeader5: sizes of the sections that follow the headers.
  auto size_field = [&](std::size_t at, const char* what) -> std::uint64_t {
    const std::int32_t v = b.i32(at);
    if (v < 0) throw InputError(fmt::format("{}: byte {}: negative {} size {}", origin, at, what, v));
    return static_cast<std::uint64_t>(v);
  };
  const std::uint64_t wfm_size = size_field(4, "wave");
  const std::uint64_t formula_size = size_field(8, "formula");
  const std::uint64_t note_size = size_field(12, "note");
  const std::uint64_t data_units_size = size_field(16, "extended data units");
  std::uint64_t dim_units_size[4], dim_labels_size[4];
  for (int i = 0; i < 4; ++i) dim_units_size[i] = size_field(20 + 4 * static_cast<std::size_t>(i), "dimension units");
  for (int i = 0; i < 4; ++i) dim_labels_size[i] = size_field(36 + 4 * static_cast<std::size_t>(i), "dimension labels");
  // WaveHeader5.
  const std::size_t w = kBinHeader;
  const std::int32_t npnts = b.i32(w + 12);
  const int type = b.i16(w + 16);
  const std::string name = c_string(bytes.substr(w + 28, 32));
  std::uint64_t dims[4];
  for (int i = 0; i < 4; ++i) {
    const std::int32_t d = b.i32(w + 68 + 4 * static_cast<std::size_t>(i));
    if (d < 0) throw InputError(fmt::format("{}: byte {}: negative dimension size {}", origin, w + 68 + 4 * i, d));
    dims[i] = static_cast<std::uint64_t>(d);
  }
  const double sfA0 = b.f64(w + 84), sfB0 = b.f64(w + 116);
  const std::string data_units = c_string(bytes.substr(w + 148, 4));
  const std::string dim0_units = c_string(bytes.substr(w + 152, 4));
  int width = 0;
  if (type & 0x01)
    throw InputError(fmt::format("{}: wave '{}' is complex: a force curve is real", origin, name));
  switch (type & ~0x40) {
    case 0x02: width = 4; break;
    case 0x04: width = 8; break;
    case 0x08: width = 1; break;
    case 0x10: width = 2; break;
    case 0x20: width = 4; break;
    default:
      throw InputError(fmt::format("{}: wave '{}': data type {} is not a number type (float, double, integer)",
                                   origin, name, type));
  }
  const bool is_float = (type & 0x06) != 0, is_unsigned = (type & 0x40) != 0;
  if (dims[0] == 0 || dims[1] == 0 || dims[2] > 1 || dims[3] > 1)
    throw InputError(fmt::format("{}: wave '{}' has dimensions {}x{}x{}x{}: a force curve is a 2-D wave of "
                                 "points x channels (Raw, Defl, ZSnsr, ...)",
                                 origin, name, dims[0], dims[1], dims[2], dims[3]));
  const std::uint64_t rows = dims[0], cols = dims[1];
  // Every size is checked against the file before anything is allocated.
  const std::uint64_t file = bytes.size();
  if (rows > file || cols > file || rows * cols != static_cast<std::uint64_t>(npnts) ||
      rows * cols * static_cast<std::uint64_t>(width) > file)
    throw InputError(fmt::format("{}: wave '{}' declares {} x {} points ({} in its header) of {} bytes: more than "
                                 "the file's {} bytes hold",
                                 origin, name, rows, cols, npnts, width, file));
  const std::uint64_t data_bytes = rows * cols * static_cast<std::uint64_t>(width);
  if (wfm_size < kWaveHeader + data_bytes)
    throw InputError(fmt::format("{}: byte 4: wave size {} is smaller than its header and {} data bytes", origin,
                                 wfm_size, data_bytes));
  std::uint64_t at = kBinHeader + wfm_size;
  auto section = [&](std::uint64_t size, const char* what) {
    if (size > file || at > file - size)
      throw InputError(fmt::format("{}: truncated: the {} ({} bytes at byte {}) ends beyond the file's {} bytes",
                                   origin, what, size, at, file));
    const std::string_view s = bytes.substr(static_cast<std::size_t>(at), static_cast<std::size_t>(size));
    at += size;
    return s;
  };
  if (kBinHeader + kWaveHeader + data_bytes > file)
    throw InputError(fmt::format("{}: truncated: the data ({} bytes) end beyond the file's {} bytes", origin,
                                 data_bytes, file));
  section(formula_size, "formula");
  const std::string_view note = section(note_size, "note");
  section(data_units_size, "extended data units");
  for (int i = 0; i < 4; ++i) section(dim_units_size[i], "extended dimension units");
  std::string_view labels;
  for (int i = 0; i < 4; ++i) {
    const std::string_view l = section(dim_labels_size[i], "dimension labels");
    if (i == 1) labels = l;
  }
  // Column labels: (cols + 1) entries (the dimension's own label first) of 32 bytes (or 256: long labels).
  std::vector<std::string> column;
  for (std::uint64_t len : {32u, 256u})
    if (labels.size() == (cols + 1) * len) {
      for (std::uint64_t j = 1; j <= cols; ++j) column.push_back(c_string(labels.substr(j * len, len)));
      break;
    }
  if (column.empty())
    throw InputError(fmt::format("{}: wave '{}': the {} columns have no labels ({} label bytes): the reader finds "
                                 "ZSnsr and Defl by their labels",
                                 origin, name, cols, labels.size()));
  auto find_column = [&](const std::vector<std::string>& names) -> int {
    for (const auto& n : names)
      for (std::size_t j = 0; j < column.size(); ++j)
        if (same_name(column[j], n)) return static_cast<int>(j);
    return -1;
  };
  auto labels_list = [&] {
    std::string s;
    for (const auto& c : column) s += (s.empty() ? "" : ", ") + c;
    return s;
  };
  const int zc = find_column(options.height.name.empty() ? std::vector<std::string>{"ZSnsr", "ZSensor"}
                                                        : std::vector<std::string>{options.height.name});
  const int dc = find_column(options.deflection.name.empty() ? std::vector<std::string>{"Defl", "Deflection"}
                                                            : std::vector<std::string>{options.deflection.name});
  const int fc = find_column(options.force.name.empty() ? std::vector<std::string>{"Force"}
                                                       : std::vector<std::string>{options.force.name});
  if (zc < 0)
    throw InputError(fmt::format("{}: wave '{}': no height column '{}' (columns: {})", origin, name,
                                 options.height.name.empty() ? "ZSnsr" : options.height.name, labels_list()));
  if (dc < 0 && fc < 0)
    throw InputError(fmt::format("{}: wave '{}': no deflection ('Defl') or force ('Force') column (columns: {})",
                                 origin, name, labels_list()));
  // One data unit for the whole wave: Asylum stores every channel in SI (m; N for Force).
  if (!data_units.empty() && data_units != "m" && data_units != "N" && data_units != "V")
    throw InputError(fmt::format("{}: wave '{}': data units '{}' (m, N or V expected)", origin, name, data_units));
  RawCurve curve;
  curve.origin = origin;
  curve.metadata.format = "ibw";
  curve.metadata.instrument = "Asylum Research";
  if (data_units.empty()) curve.notes.push_back("the wave has no data units: SI (m) assumed, as Asylum writes");
  auto read_column = [&](int j) {
    std::vector<double> out(static_cast<std::size_t>(rows));
    const std::size_t base = kBinHeader + kWaveHeader + static_cast<std::size_t>(j) * static_cast<std::size_t>(rows) *
                                                           static_cast<std::size_t>(width);
    for (std::size_t i = 0; i < rows; ++i) {
      const std::size_t p = base + i * static_cast<std::size_t>(width);
      double v;
      if (is_float) v = width == 4 ? static_cast<double>(b.f32(p)) : b.f64(p);
      else if (is_unsigned) v = static_cast<double>(b.u(p, width));
      else {
        const int shift = 64 - 8 * width;
        v = static_cast<double>(static_cast<std::int64_t>(b.u(p, width) << shift) >> shift);
      }
      if (std::isinf(v))
        throw InputError(fmt::format("{}: wave '{}', point {}, column '{}': infinite value", origin, name, i,
                                     column[static_cast<std::size_t>(j)]));
      out[i] = v;
    }
    return out;
  };
  std::vector<double> z = read_column(zc);
  const double sign = options.height_direction == "away" ? 1.0 : -1.0;  // ZSnsr grows towards the sample
  if (options.height_direction != "auto" && options.height_direction != "away" && options.height_direction != "towards")
    throw InputError(fmt::format("{}: height direction '{}' is not one of auto, away, towards", origin,
                                 options.height_direction));
  for (double& v : z) v *= sign;
  std::vector<double> defl, force;
  if (dc >= 0) defl = read_column(dc);
  if (fc >= 0) force = read_column(fc);
  const bool defl_volts = data_units == "V";
  // Calibration from the note.
  auto meta = [&](const char* key, double& target, bool required_positive) {
    const auto v = note_number(note, key);
    if (!v) return;
    if (*v > 0) target = *v;
    else if (required_positive)
      throw InputError(fmt::format("{}: note: '{}: {}': must be positive", origin, key, *v));
    else
      curve.notes.push_back(fmt::format("note: '{}: {}' is not positive: ignored (no thermal tune)", key, *v));
  };
  meta("SpringConstant", curve.metadata.spring_constant, true);
  meta("InvOLS", curve.metadata.invols, true);
  meta("ThermalFrequency", curve.metadata.resonance_frequency, false);
  meta("ThermalQ", curve.metadata.quality_factor, false);
  // Trailing NaN padding (every chosen column NaN at the end) is dropped; a NaN elsewhere is an error.
  std::size_t n = static_cast<std::size_t>(rows);
  auto empty_row = [&](std::size_t i) {
    return std::isnan(z[i]) && (defl.empty() || std::isnan(defl[i])) && (force.empty() || std::isnan(force[i]));
  };
  while (n > 0 && empty_row(n - 1)) --n;
  if (n < rows) curve.notes.push_back(fmt::format("points {}-{}: NaN padding at the end dropped", n, rows - 1));
  if (n == 0) throw InputError(fmt::format("{}: wave '{}': every point is NaN", origin, name));
  for (std::size_t i = 0; i < n; ++i) {
    auto bad = [&](const std::vector<double>& v) { return !v.empty() && std::isnan(v[i]); };
    if (bad(z) || bad(defl) || bad(force))
      throw InputError(fmt::format("{}: wave '{}', point {}, column '{}': NaN in the middle of the data", origin, name,
                                   i, column[static_cast<std::size_t>(bad(z) ? zc : bad(defl) ? dc : fc)]));
  }
  // Segments from the note's Indexes / Direction, else split at the turning point of the height.
  std::vector<std::pair<std::size_t, SegmentKind>> starts;
  const auto idx_text = note_text(note, "Indexes");
  const auto dir_text = note_text(note, "Direction");
  if (idx_text) {
    const auto idx = number_list(*idx_text);
    const auto dir = dir_text ? number_list(*dir_text) : std::nullopt;
    if (!idx || idx->size() < 2)
      throw InputError(fmt::format("{}: note: 'Indexes:{}' is not a list of point indices", origin, *idx_text));
    for (std::size_t k = 0; k < idx->size(); ++k) {
      const double v = (*idx)[k];
      if (!(v >= 0) || v != std::floor(v) || v >= static_cast<double>(rows) || (k > 0 && v < (*idx)[k - 1]))
        throw InputError(fmt::format("{}: note: 'Indexes:{}': entry {} ({}) is not an increasing point index below {}",
                                     origin, *idx_text, k + 1, v, rows));
    }
    for (std::size_t k = 1; k < idx->size(); ++k) {
      const std::size_t begin = k == 1 ? 0 : static_cast<std::size_t>((*idx)[k - 1]) + 1;
      SegmentKind kind = SegmentKind::unknown;
      if (dir && k < dir->size()) {
        const double d = (*dir)[k];
        kind = d > 0 ? SegmentKind::approach : d < 0 ? SegmentKind::retract : d == 0 ? SegmentKind::pause
                                                                                     : SegmentKind::unknown;
      }
      starts.emplace_back(begin, kind);
    }
  } else {
    starts.emplace_back(0, SegmentKind::unknown);
    std::size_t imin = 0;
    for (std::size_t i = 1; i < n; ++i)
      if (z[i] < z[imin]) imin = i;
    if (imin > 0 && imin + 1 < n) starts.emplace_back(imin + 1, SegmentKind::unknown);
    curve.notes.push_back("the note has no 'Indexes': split at the lowest height");
  }
  const bool have_time = dim0_units == "s" && std::isfinite(sfA0) && sfA0 > 0 && std::isfinite(sfB0);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::size_t begin = std::min(starts[k].first, n);
    const std::size_t end = k + 1 < starts.size() ? std::min(starts[k + 1].first, n) : n;
    if (end <= begin) continue;
    Segment s;
    s.kind = starts[k].second;
    s.height.assign(z.begin() + static_cast<std::ptrdiff_t>(begin), z.begin() + static_cast<std::ptrdiff_t>(end));
    if (!defl.empty())
      (defl_volts ? s.deflection_volts : s.deflection)
          .assign(defl.begin() + static_cast<std::ptrdiff_t>(begin), defl.begin() + static_cast<std::ptrdiff_t>(end));
    if (!force.empty())
      s.force.assign(force.begin() + static_cast<std::ptrdiff_t>(begin), force.begin() + static_cast<std::ptrdiff_t>(end));
    if (have_time) {
      s.time.resize(end - begin);
      for (std::size_t i = begin; i < end; ++i) s.time[i - begin] = sfB0 + sfA0 * static_cast<double>(i);
    }
    if (s.kind == SegmentKind::unknown && s.height.size() >= 2)
      s.kind = s.height.back() < s.height.front() ? SegmentKind::approach : SegmentKind::retract;
    curve.segments.push_back(std::move(s));
  }
  std::vector<RawCurve> out;
  out.push_back(std::move(curve));
  return out;
}

}  // namespace afmkit::io::curves::detail
