// 16-bit greyscale PNG reading and writing through libpng (rules in include/afmkit/scan/png16.hpp).
//
// libpng reports errors by longjmp to the setjmp point of the caller. The functions that call libpng under setjmp
// (decode, encode) hold no object with a destructor and let no C++ exception cross a libpng frame: every C++ object
// lives in the caller and is reached through a context struct, and the I/O callbacks report failures with
// png_error (a longjmp) rather than throwing.
#include "afmkit/scan/png16.hpp"

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <png.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "file_bytes.hpp"

namespace afmkit::scan {

namespace {

constexpr std::uintmax_t png_max_file_bytes = std::uintmax_t{512} << 20;
constexpr unsigned long max_pixels = 1UL << 26;

struct Context {
  std::string_view input;   // reading
  std::size_t position = 0;
  std::string* output = nullptr;  // writing
  char message[256] = "";   // libpng's error message
};

void on_error(png_structp png, png_const_charp message) {
  auto* ctx = static_cast<Context*>(png_get_error_ptr(png));
  std::snprintf(ctx->message, sizeof ctx->message, "%s", message ? message : "unknown libpng error");
  png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}

void read_bytes(png_structp png, png_bytep out, png_size_t length) {
  auto* ctx = static_cast<Context*>(png_get_io_ptr(png));
  if (length > ctx->input.size() - ctx->position) png_error(png, "unexpected end of file");
  std::memcpy(out, ctx->input.data() + ctx->position, length);
  ctx->position += length;
}

void write_bytes(png_structp png, png_bytep data, png_size_t length) {
  auto* ctx = static_cast<Context*>(png_get_io_ptr(png));
  bool failed = false;
  try {
    ctx->output->append(reinterpret_cast<const char*>(data), length);
  } catch (...) {
    failed = true;
  }
  if (failed) png_error(png, "out of memory while encoding");
}
void flush_bytes(png_structp) {}

struct Header {
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, colour_type = 0;
};

enum class Stage { header, decoded };

/// Reads the header into `h`; when it is 16-bit grey and small enough, the rows into `raw` (width · 2 bytes each,
/// big-endian). Returns false on a libpng error (message in ctx).
bool decode(png_structp png, png_infop info, Header& h, std::vector<unsigned char>& raw,
            std::vector<png_bytep>& rows, Stage& stage) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  png_get_IHDR(png, info, &h.width, &h.height, &h.bit_depth, &h.colour_type, nullptr, nullptr, nullptr);
  stage = Stage::header;
  if (h.bit_depth != 16 || h.colour_type != PNG_COLOR_TYPE_GRAY) return true;
  if (static_cast<unsigned long>(h.width) * h.height > max_pixels) return true;
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const std::size_t row_bytes = static_cast<std::size_t>(h.width) * 2;
  raw.resize(row_bytes * h.height);
  rows.resize(h.height);
  for (png_uint_32 j = 0; j < h.height; ++j) rows[j] = raw.data() + j * row_bytes;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  stage = Stage::decoded;
  return true;
}

bool encode(png_structp png, png_infop info, const Grey16& image, std::vector<png_bytep>& rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 16,
               PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  return true;
}

std::string colour_type_name(int t) {
  switch (t) {
    case PNG_COLOR_TYPE_GRAY: return "greyscale";
    case PNG_COLOR_TYPE_GRAY_ALPHA: return "greyscale with alpha";
    case PNG_COLOR_TYPE_RGB: return "RGB";
    case PNG_COLOR_TYPE_RGB_ALPHA: return "RGB with alpha";
    case PNG_COLOR_TYPE_PALETTE: return "palette";
    default: return "unknown";
  }
}

}  // namespace

Grey16 parse_png16(std::string_view bytes, const std::string& origin) {
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0)
    throw InputError(fmt::format("{}: not a PNG file (no PNG signature)", origin));
  Context ctx;
  ctx.input = bytes;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &ctx, on_error, on_warning);
  if (!png) throw InputError(fmt::format("{}: cannot start the PNG decoder", origin));
  png_infop info = png_create_info_struct(png);
  struct Guard {
    png_structp* png;
    png_infop* info;
    ~Guard() { png_destroy_read_struct(png, info, nullptr); }
  } guard{&png, &info};
  if (!info) throw InputError(fmt::format("{}: cannot start the PNG decoder", origin));
  png_set_read_fn(png, &ctx, read_bytes);
  png_set_user_limits(png, 1u << 24, 1u << 24);

  Header h;
  std::vector<unsigned char> raw;
  std::vector<png_bytep> rows;
  Stage stage = Stage::header;
  if (!decode(png, info, h, raw, rows, stage)) throw InputError(fmt::format("{}: bad PNG: {}", origin, ctx.message));
  if (h.bit_depth != 16 || h.colour_type != PNG_COLOR_TYPE_GRAY)
    throw InputError(fmt::format("{}: not a 16-bit greyscale PNG: bit depth {}, colour type {} ({})", origin,
                                 h.bit_depth, h.colour_type, colour_type_name(h.colour_type)));
  if (stage != Stage::decoded)
    throw InputError(fmt::format("{}: PNG of {} · {} pixels: more than the {} allowed", origin, h.width, h.height,
                                 max_pixels));
  Grey16 image;
  image.width = static_cast<long>(h.width);
  image.height = static_cast<long>(h.height);
  image.pixels.resize(raw.size() / 2);
  for (std::size_t k = 0; k < image.pixels.size(); ++k)
    image.pixels[k] = static_cast<std::uint16_t>((raw[2 * k] << 8) | raw[2 * k + 1]);
  return image;
}

Grey16 read_png16(const std::string& path) {
  return parse_png16(detail::read_file_bytes(path, "PNG", png_max_file_bytes), path);
}

std::string format_png16(const Grey16& image) {
  constexpr long max_side = 2147483647L;
  if (image.width < 1 || image.width > max_side)
    throw InvalidParameter("width", fmt::format("width = {}: must be 1 to {}", image.width, max_side));
  if (image.height < 1 || image.height > max_side)
    throw InvalidParameter("height", fmt::format("height = {}: must be 1 to {}", image.height, max_side));
  const auto w = static_cast<std::size_t>(image.width);
  const auto hgt = static_cast<std::size_t>(image.height);
  if (w > image.pixels.size() / hgt || w * hgt != image.pixels.size())
    throw InvalidParameter("pixels", fmt::format("pixels has {} values, width · height = {} · {}",
                                                 image.pixels.size(), image.width, image.height));
  std::vector<unsigned char> raw(2 * image.pixels.size());
  for (std::size_t k = 0; k < image.pixels.size(); ++k) {
    raw[2 * k] = static_cast<unsigned char>(image.pixels[k] >> 8);
    raw[2 * k + 1] = static_cast<unsigned char>(image.pixels[k] & 0xFF);
  }
  std::vector<png_bytep> rows(hgt);
  for (std::size_t j = 0; j < hgt; ++j) rows[j] = raw.data() + j * 2 * w;

  std::string out;
  Context ctx;
  ctx.output = &out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &ctx, on_error, on_warning);
  if (!png) throw InputError("cannot start the PNG encoder");
  png_infop info = png_create_info_struct(png);
  struct Guard {
    png_structp* png;
    png_infop* info;
    ~Guard() { png_destroy_write_struct(png, info); }
  } guard{&png, &info};
  if (!info) throw InputError("cannot start the PNG encoder");
  png_set_write_fn(png, &ctx, write_bytes, flush_bytes);
  if (!encode(png, info, image, rows)) throw InputError(fmt::format("PNG encoding failed: {}", ctx.message));
  return out;
}

Grey16 to_grey16(const HeightMap& map) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : map.data())
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  Grey16 image;
  image.width = map.x_resolution();
  image.height = map.y_resolution();
  image.pixels.assign(map.size(), 0);
  if (!(hi > lo)) return image;
  // Halved values: hi - lo cannot overflow (halving is exact for normal numbers, so the quotient is unchanged).
  const double half_lo = 0.5 * lo, range = 0.5 * hi - half_lo;
  for (std::size_t k = 0; k < map.size(); ++k) {
    const double v = map.data()[k];
    if (!std::isfinite(v)) continue;
    const double level = std::round((0.5 * v - half_lo) / range * 65535.0);
    image.pixels[k] = level >= 0.0 ? static_cast<std::uint16_t>(std::min(level, 65535.0)) : std::uint16_t{0};
  }
  return image;
}

void write_png16(const std::string& path, const HeightMap& map) {
  io::write_file_atomic(path, format_png16(to_grey16(map)));
}

}  // namespace afmkit::scan
