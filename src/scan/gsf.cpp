// Gwyddion Simple Field files (format, invalid-pixel convention and reader rules in include/afmkit/scan/gsf.hpp).
#include "afmkit/scan/gsf.hpp"

#include <cmath>
#include <filesystem>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/number.hpp"
#include "afmkit/io/output.hpp"
#include "binary_header.hpp"
#include "file_bytes.hpp"

namespace afmkit::scan {

namespace {

constexpr std::size_t gsf_alignment = 4;
constexpr long max_resolution = 1L << 24;
constexpr std::uintmax_t gsf_max_file_bytes = std::uintmax_t{2} << 30;

std::string header_of(const HeightMap& map, std::string_view z_unit, const std::string& title) {
  std::string h(gsf_magic);
  h += fmt::format("XRes = {}\nYRes = {}\n", map.x_resolution(), map.y_resolution());
  h += fmt::format("XReal = {}\nYReal = {}\n", map.x_size(), map.y_size());
  h += fmt::format("XOffset = {}\nYOffset = {}\n", map.x_offset(), map.y_offset());
  h += "XYUnits = m\n";
  if (!z_unit.empty()) h += fmt::format("ZUnits = {}\n", z_unit);
  if (!title.empty()) h += fmt::format("Title = {}\n", title);
  h.append(gsf_alignment - h.size() % gsf_alignment, '\0');
  return h;
}

double real_field(const detail::BinaryHeader& h, std::string_view key, double fallback, bool positive,
                  const std::string& origin) {
  const detail::HeaderField* f = h.find(key);
  if (!f) return fallback;
  const auto v = io::parse_real(f->value);
  if (!v) throw InputError(fmt::format("{}:{}: {} = {} is not a number", origin, f->line, key, detail::shown(f->value)));
  if (!std::isfinite(*v))
    throw InputError(fmt::format("{}:{}: {} = {} is not finite", origin, f->line, key, detail::shown(f->value)));
  if (positive && !(*v > 0))
    throw InputError(fmt::format("{}:{}: {} = {} must be > 0", origin, f->line, key, detail::shown(f->value)));
  return *v;
}


/// The grid and the raw float values of a GSF file (values as doubles, non-finite ones kept).
struct RawGsf {
  Grid grid;
  std::vector<double> values;
  detail::BinaryHeader header;
};

RawGsf parse_raw(std::string_view bytes, const std::string& origin) {
  RawGsf raw;
  raw.header = detail::parse_binary_header(bytes, gsf_magic, gsf_alignment, "Gwyddion Simple Field", origin);
  const detail::BinaryHeader& h = raw.header;
  raw.grid.x_resolution = detail::header_count(h, "XRes", max_resolution, true, origin);
  raw.grid.y_resolution = detail::header_count(h, "YRes", max_resolution, true, origin);
  raw.grid.x_size = real_field(h, "XReal", 1.0, true, origin);
  raw.grid.y_size = real_field(h, "YReal", 1.0, true, origin);
  raw.grid.x_offset = real_field(h, "XOffset", 0.0, false, origin);
  raw.grid.y_offset = real_field(h, "YOffset", 0.0, false, origin);
  if (const detail::HeaderField* f = h.find("XYUnits"); f && f->value != "m")
    throw InputError(fmt::format("{}:{}: XYUnits = {}: only metres ('m') are supported for x and y", origin, f->line,
                                 detail::shown(f->value)));
  const auto count = static_cast<std::size_t>(raw.grid.x_resolution) * static_cast<std::size_t>(raw.grid.y_resolution);
  const std::size_t data_bytes = count * 4;  // < 2^50: no overflow
  if (bytes.size() - h.data_start != data_bytes)
    detail::throw_size_mismatch(h, bytes.size(), gsf_alignment,
                                fmt::format("XRes · YRes = {} · {} float32 values", raw.grid.x_resolution,
                                            raw.grid.y_resolution),
                                data_bytes, origin);
  raw.values.resize(count);
  const char* p = bytes.data() + h.data_start;
  for (std::size_t k = 0; k < count; ++k) raw.values[k] = static_cast<double>(detail::load_le32(p + 4 * k));
  return raw;
}

GsfField make_field(RawGsf raw, std::vector<std::uint8_t> valid, const std::string& origin) {
  std::string z_unit = detail::header_text(raw.header, "ZUnits", origin);
  std::string title = detail::header_text(raw.header, "Title", origin);
  std::vector<std::pair<std::string, std::string>> extra;
  for (const detail::HeaderField& f : raw.header.fields)
    if (f.key != "XRes" && f.key != "YRes" && f.key != "XReal" && f.key != "YReal" && f.key != "XOffset" &&
        f.key != "YOffset" && f.key != "XYUnits" && f.key != "ZUnits" && f.key != "Title")
      extra.emplace_back(f.key, f.value);
  try {
    return GsfField{HeightMap(raw.grid, std::move(raw.values), std::move(z_unit), std::move(valid)),
                    std::move(title), std::move(extra)};
  } catch (const InvalidParameter& e) {  // not expected: every field is checked above
    throw InputError(fmt::format("{}: {}", origin, e.what()));
  }
}

}  // namespace

std::string format_gsf(const HeightMap& map, const std::string& title) {
  detail::check_header_text("title", title);
  double mean = 0.0;  // running mean: no overflow for values near the float32 limit
  std::size_t n = 0;
  constexpr double float_max = std::numeric_limits<float>::max();
  for (std::size_t k = 0; k < map.size(); ++k) {
    const double v = map.data()[k];
    if (!std::isfinite(v)) continue;
    if (std::fabs(v) > float_max) {
      const auto columns = static_cast<std::size_t>(map.x_resolution());
      throw InvalidParameter("data", fmt::format("{}the value {} {} at pixel (column {}, row {}) is beyond the float32 "
                                                 "range of a GSF file (|z| <= {:.4g})",
                                                 title.empty() ? "" : fmt::format("{}: ", title), v, map.z_unit(),
                                                 k % columns, k / columns, float_max));
    }
    ++n;
    mean += (v - mean) / static_cast<double>(n);
  }
  const auto fill = static_cast<float>(mean);
  std::string out = header_of(map, map.z_unit(), title);
  out.reserve(out.size() + 4 * map.size());
  for (double v : map.data()) detail::append_le32(out, std::isfinite(v) ? static_cast<float>(v) : fill);
  return out;
}

std::string format_gsf_mask(const HeightMap& map, const std::string& title) {
  detail::check_header_text("title", title);
  std::string out = header_of(map, "", title.empty() ? "validity mask" : title + " validity mask");
  out.reserve(out.size() + 4 * map.size());
  for (long j = 0; j < map.y_resolution(); ++j)
    for (long i = 0; i < map.x_resolution(); ++i) detail::append_le32(out, map.valid(i, j) ? 1.0f : 0.0f);
  return out;
}

std::string gsf_mask_path(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string extension = p.has_extension() ? p.extension().string() : ".gsf";
  return (p.parent_path() / (p.stem().string() + "_mask" + extension)).string();
}

std::vector<std::string> write_gsf(const std::string& path, const HeightMap& map, const std::string& title) {
  std::string data = format_gsf(map, title);
  std::string mask = map.has_mask() ? format_gsf_mask(map, title) : std::string();
  io::OutputSet set;  // the field and its mask: both or neither
  set.add(path, data);
  std::vector<std::string> written{path};
  if (map.has_mask()) {
    const std::string mask_path = gsf_mask_path(path);
    set.add(mask_path, mask);
    written.push_back(mask_path);
  }
  set.commit();
  return written;
}

GsfField parse_gsf(std::string_view bytes, const std::string& origin) {
  RawGsf raw = parse_raw(bytes, origin);
  std::vector<std::uint8_t> valid;
  for (std::size_t k = 0; k < raw.values.size(); ++k) {
    if (std::isfinite(raw.values[k])) continue;
    if (valid.empty()) valid.assign(raw.values.size(), 1);
    valid[k] = 0;
  }
  return make_field(std::move(raw), std::move(valid), origin);
}

GsfField parse_gsf_with_mask(std::string_view bytes, const std::string& origin, std::string_view mask_bytes,
                             const std::string& mask_origin) {
  RawGsf raw = parse_raw(bytes, origin);
  const RawGsf mask = parse_raw(mask_bytes, mask_origin);
  if (mask.grid.x_resolution != raw.grid.x_resolution || mask.grid.y_resolution != raw.grid.y_resolution)
    throw InputError(fmt::format("{}: the mask has XRes · YRes = {} · {}, the data file {} has {} · {}", mask_origin,
                                 mask.grid.x_resolution, mask.grid.y_resolution, origin, raw.grid.x_resolution,
                                 raw.grid.y_resolution));
  std::vector<std::uint8_t> valid(raw.values.size(), 1);
  const auto columns = static_cast<std::size_t>(raw.grid.x_resolution);
  for (std::size_t k = 0; k < raw.values.size(); ++k) {
    const double m = mask.values[k];
    if (m != 0.0 && m != 1.0)
      throw InputError(fmt::format("{}: mask value {} at column {}, row {}: a mask holds 1 (valid) or 0 (invalid)",
                                   mask_origin, m, k % columns, k / columns));
    valid[k] = (m == 1.0 && std::isfinite(raw.values[k])) ? 1 : 0;
  }
  return make_field(std::move(raw), std::move(valid), origin);
}

GsfField read_gsf(const std::string& path) {
  return parse_gsf(detail::read_file_bytes(path, "GSF", gsf_max_file_bytes), path);
}

GsfField read_gsf_with_mask(const std::string& path, const std::string& mask_path) {
  return parse_gsf_with_mask(detail::read_file_bytes(path, "GSF", gsf_max_file_bytes), path,
                             detail::read_file_bytes(mask_path, "GSF mask", gsf_max_file_bytes), mask_path);
}

}  // namespace afmkit::scan
