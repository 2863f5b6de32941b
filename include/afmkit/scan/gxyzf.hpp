#pragma once
// Gwyddion XYZ Field (.gxyzf) 1.0 files: scattered points (x, y) with one or more values each — the raw point cloud
// of a spiral scan, before any interpolation to a grid. Gwyddion 2.31 or later reads them.
// Format (gwyddion.net/documentation/user-guide-en/gxyzf.html; Gwyddion's modules/file/gxyzffile.c):
//   "Gwyddion XYZ Field 1.0\n"                       magic line
//   "NChannels = 2\n" "NPoints = 1000\n" ...         `Key = Value` lines: NChannels, NPoints mandatory; XYUnits,
//                                                    ZUnits1 … ZUnitsN, Title1 … TitleN optional
//   1 to 8 NUL bytes                                 so that the data starts at a multiple of 8 bytes
//   per point: x, y, z1 … zN                         little-endian IEEE float64
// Writing: XYUnits, ZUnits<k>, Title<k> are written when not empty. Reading: a ZUnits field (no number) applies to
// every channel, as in Gwyddion; other fields (e.g. Gwyddion's XRes / YRes grid hints) are ignored. Reader rules
// (InputError "<file>: …" naming the field or "<file>:<line>: …"): missing magic line; bad padding (no NUL, padding
// bytes not NUL up to a multiple of 8, more NULs than that); a header line without '=' or a duplicate field;
// NChannels missing / not in [1, 1024] (Gwyddion's limit); NPoints missing / not a positive integer; units or titles
// with a control character; data length != NPoints · (NChannels + 2) · 8 bytes ("size mismatch"); a coordinate or
// value that is not finite (naming the point and the column).
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace afmkit::scan {

inline constexpr std::string_view gxyzf_magic = "Gwyddion XYZ Field 1.0\n";

/// One value channel of a point cloud: a value per point.
struct XyzChannel {
  std::string title;  ///< e.g. "Height" ("" = none)
  std::string unit;   ///< e.g. "m" ("" = dimensionless)
  std::vector<double> values;
};

/// Scattered points (x, y) [xy_unit, metres by default] with 1 to 1024 value channels.
class XyzField {
 public:
  /// InvalidParameter naming the field: x and y of different lengths or empty ("y", "x"); no channel or more than
  /// 1024 ("channels"); a channel with another number of values ("channels[k].values"); a non-finite coordinate or
  /// value; a title or unit with a control character or a leading / trailing blank.
  XyzField(std::vector<double> x, std::vector<double> y, std::vector<XyzChannel> channels, std::string xy_unit = "m");

  std::size_t size() const { return x_.size(); }  ///< number of points
  const std::vector<double>& x() const& { return x_; }
  std::vector<double> x() && { return std::move(x_); }  // a temporary gives its value
  const std::vector<double>& y() const& { return y_; }
  std::vector<double> y() && { return std::move(y_); }  // a temporary gives its value
  const std::vector<XyzChannel>& channels() const& { return channels_; }
  std::vector<XyzChannel> channels() && { return std::move(channels_); }  // a temporary gives its value
  const std::string& xy_unit() const& { return xy_unit_; }
  std::string xy_unit() && { return std::move(xy_unit_); }  // a temporary gives its value

 private:
  std::vector<double> x_, y_;
  std::vector<XyzChannel> channels_;
  std::string xy_unit_;
};

/// The bytes of the GXYZF file of `field`.
std::string format_gxyzf(const XyzField& field);
/// Writes format_gxyzf(field) to `path` atomically (InputError on an I/O failure).
void write_gxyzf(const std::string& path, const XyzField& field);
/// The GXYZF file held in `bytes`; `origin` names it in messages.
XyzField parse_gxyzf(std::string_view bytes, const std::string& origin);
/// The GXYZF file at `path` (at most 2 GiB).
XyzField read_gxyzf(const std::string& path);

}  // namespace afmkit::scan
