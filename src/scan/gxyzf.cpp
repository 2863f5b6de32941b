// Gwyddion XYZ Field files (format and reader rules in include/afmkit/scan/gxyzf.hpp).
#include "afmkit/scan/gxyzf.hpp"

#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "binary_header.hpp"
#include "file_bytes.hpp"

namespace afmkit::scan {

namespace {
constexpr std::size_t gxyzf_alignment = 8;
constexpr long max_channels = 1024;
constexpr long max_points = 1L << 40;
constexpr std::uintmax_t gxyzf_max_file_bytes = std::uintmax_t{2} << 30;

void check_finite(const std::vector<double>& v, const std::string& name) {
  for (std::size_t k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]))
      throw InvalidParameter(name, fmt::format("{}[{}] = {}: must be finite", name, k, v[k]));
}

}  // namespace

XyzField::XyzField(std::vector<double> x, std::vector<double> y, std::vector<XyzChannel> channels, std::string xy_unit)
    : x_(std::move(x)), y_(std::move(y)), channels_(std::move(channels)), xy_unit_(std::move(xy_unit)) {
  if (x_.empty()) throw InvalidParameter("x", "x is empty: a point cloud needs at least one point");
  if (y_.size() != x_.size())
    throw InvalidParameter("y", fmt::format("y has {} values, x has {}: one (x, y) per point", y_.size(), x_.size()));
  if (channels_.empty() || channels_.size() > static_cast<std::size_t>(max_channels))
    throw InvalidParameter("channels", fmt::format("{} channels: must be 1 to {}", channels_.size(), max_channels));
  check_finite(x_, "x");
  check_finite(y_, "y");
  detail::check_header_text("xy_unit", xy_unit_);
  for (std::size_t c = 0; c < channels_.size(); ++c) {
    const std::string name = fmt::format("channels[{}]", c);
    if (channels_[c].values.size() != x_.size())
      throw InvalidParameter(name + ".values", fmt::format("{}.values has {} values for {} points", name,
                                                           channels_[c].values.size(), x_.size()));
    check_finite(channels_[c].values, name + ".values");
    detail::check_header_text(name + ".title", channels_[c].title);
    detail::check_header_text(name + ".unit", channels_[c].unit);
  }
}

std::string format_gxyzf(const XyzField& field) {
  std::string out(gxyzf_magic);
  out += fmt::format("NChannels = {}\nNPoints = {}\n", field.channels().size(), field.size());
  if (!field.xy_unit().empty()) out += fmt::format("XYUnits = {}\n", field.xy_unit());
  for (std::size_t c = 0; c < field.channels().size(); ++c) {
    if (!field.channels()[c].unit.empty()) out += fmt::format("ZUnits{} = {}\n", c + 1, field.channels()[c].unit);
    if (!field.channels()[c].title.empty()) out += fmt::format("Title{} = {}\n", c + 1, field.channels()[c].title);
  }
  out.append(gxyzf_alignment - out.size() % gxyzf_alignment, '\0');
  out.reserve(out.size() + 8 * field.size() * (field.channels().size() + 2));
  for (std::size_t k = 0; k < field.size(); ++k) {
    detail::append_le64(out, field.x()[k]);
    detail::append_le64(out, field.y()[k]);
    for (const XyzChannel& ch : field.channels()) detail::append_le64(out, ch.values[k]);
  }
  return out;
}

void write_gxyzf(const std::string& path, const XyzField& field) { io::write_file_atomic(path, format_gxyzf(field)); }

XyzField parse_gxyzf(std::string_view bytes, const std::string& origin) {
  const detail::BinaryHeader h =
      detail::parse_binary_header(bytes, gxyzf_magic, gxyzf_alignment, "Gwyddion XYZ Field", origin);
  const long nchannels = detail::header_count(h, "NChannels", max_channels, true, origin);
  const long npoints = detail::header_count(h, "NPoints", max_points, true, origin);
  const std::string xy_unit = detail::header_text(h, "XYUnits", origin);
  const std::string common_unit = detail::header_text(h, "ZUnits", origin);
  const auto columns = static_cast<std::size_t>(nchannels) + 2;
  const auto count = static_cast<std::size_t>(npoints);
  const std::size_t data_bytes = count * columns * 8;  // < 2^51: no overflow
  if (bytes.size() - h.data_start != data_bytes)
    detail::throw_size_mismatch(h, bytes.size(), gxyzf_alignment,
                                fmt::format("NPoints · (NChannels + 2) = {} · {} float64 values", npoints, columns),
                                data_bytes, origin);
  std::vector<double> x(count), y(count);
  std::vector<XyzChannel> channels(static_cast<std::size_t>(nchannels));
  for (std::size_t c = 0; c < channels.size(); ++c) {
    channels[c].unit = h.find("ZUnits") ? common_unit : detail::header_text(h, fmt::format("ZUnits{}", c + 1), origin);
    channels[c].title = detail::header_text(h, fmt::format("Title{}", c + 1), origin);
    channels[c].values.resize(count);
  }
  const char* p = bytes.data() + h.data_start;
  for (std::size_t k = 0; k < count; ++k) {
    for (std::size_t c = 0; c < columns; ++c) {
      const double v = detail::load_le64(p + 8 * (k * columns + c));
      if (!std::isfinite(v))
        throw InputError(fmt::format("{}: point {} (0-based): {} = {} is not finite", origin, k,
                                     c == 0 ? std::string("x") : c == 1 ? std::string("y") : fmt::format("z{}", c - 1),
                                     v));
      if (c == 0)
        x[k] = v;
      else if (c == 1)
        y[k] = v;
      else
        channels[c - 2].values[k] = v;
    }
  }
  try {
    return XyzField(std::move(x), std::move(y), std::move(channels), xy_unit);
  } catch (const InvalidParameter& e) {  // not expected: every field is checked above
    throw InputError(fmt::format("{}: {}", origin, e.what()));
  }
}

XyzField read_gxyzf(const std::string& path) {
  return parse_gxyzf(detail::read_file_bytes(path, "GXYZF", gxyzf_max_file_bytes), path);
}

}  // namespace afmkit::scan
