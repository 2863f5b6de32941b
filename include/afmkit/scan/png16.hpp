#pragma once
// 16-bit greyscale PNG files: a preview of a height map that any image viewer shows (Gwyddion can import it too, as
// a high-depth image, but the physical scale is lost). Uses libpng; its errors become afmkit::InputError.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "afmkit/scan/height_map.hpp"

namespace afmkit::scan {

/// A 16-bit greyscale image, row-major from the top row: grey of column i, row j at pixels[j · width + i].
struct Grey16 {
  long width = 0;
  long height = 0;
  std::vector<std::uint16_t> pixels;
};

/// The image in the PNG held in `bytes` (`origin` names it in messages). InputError: not a PNG (bad signature), a
/// PNG that is not 16-bit greyscale without alpha (the message names the bit depth and colour type found), more
/// than 2^26 pixels, or any libpng error (truncated file, bad CRC, corrupt compressed data), with libpng's message.
/// Interlaced images are read too; ancillary chunks (gamma, text, …) are ignored.
Grey16 parse_png16(std::string_view bytes, const std::string& origin);
/// The image in the PNG file at `path` (at most 512 MiB).
Grey16 read_png16(const std::string& path);

/// The bytes of a 16-bit greyscale, non-interlaced PNG of `image` (InvalidParameter "pixels" when its size is not
/// width · height, "width" / "height" when < 1 or > 2^31 - 1).
std::string format_png16(const Grey16& image);
/// `map` as grey levels: the valid values' range [min, max] scaled linearly to 0 … 65535 (rounded to nearest;
/// integer data spanning exactly 0 … 65535 is kept as it is), invalid pixels 0; a map whose valid values are all
/// equal (or that has no valid pixel) is all 0.
Grey16 to_grey16(const HeightMap& map);
/// Writes format_png16(to_grey16(map)) to `path` atomically (a preview: the scale is lost).
void write_png16(const std::string& path, const HeightMap& map);

}  // namespace afmkit::scan
