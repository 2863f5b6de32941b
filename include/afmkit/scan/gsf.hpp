#pragma once
// Gwyddion Simple Field (.gsf) 1.0 files: one channel of 2D data that Gwyddion (2.20 or later) opens directly.
// Format (gwyddion.net/documentation/user-guide-en/gsf.html; Gwyddion's modules/file/gsffile.c):
//   "Gwyddion Simple Field 1.0\n"                     magic line
//   "XRes = 256\n" "YRes = 256\n" ...                  `Key = Value` lines, UTF-8, LF ends
//   1 to 4 NUL bytes                                   so that the data starts at a multiple of 4 bytes
//   XRes · YRes little-endian IEEE float32 values      row by row from the top row, each row left to right
// Header fields: XRes, YRes mandatory (positive integers); XReal, YReal (physical size, default 1), XOffset,
// YOffset (default 0), XYUnits, ZUnits, Title optional; any other field is metadata (kept in `extra`).
//
// Invalid pixels. GSF has no mask, and Gwyddion "has no concept of bad data points": its importers mark them with
// a mask and replace their values by the average of the good points (gwy_app_channel_remove_bad_data in
// Gwyddion's app/gwymoduleutils-file.c). The GSF importer of Gwyddion 2.x (gsffile.c) reads the floats as they
// are — a NaN would reach its statistics and levelling. So write_gsf does what Gwyddion does on import: invalid
// pixels get the mean of the valid pixels (0 when none is valid) in the data file, and the mask goes to a second
// GSF next to it, gsf_mask_path(path) = "<stem>_mask.gsf", holding 1 at valid and 0 at invalid pixels (open both
// in Gwyddion and turn the second into a mask, e.g. by marking it at threshold 0.5). Reading: a
// non-finite float in a file (another tool's NaN) makes that pixel invalid; read_gsf_with_mask also applies a
// mask file.
//
// Reader rules (InputError "<file>: …" naming the field, or "<file>:<line>: …" for a header line): missing magic
// line; no NUL after the header; padding bytes not NUL up to the next multiple of 4, or more NULs than that with the
// data size off by as many bytes ("bad padding"); a header line without '=' or with an empty key; a duplicate
// field; XRes / YRes missing, not digits, 0 or above 2^24; XReal / YReal not a number, not finite or <= 0;
// XOffset / YOffset not a finite number; XYUnits other than "m"; ZUnits / Title with a control character; data
// shorter or longer than XRes · YRes · 4 bytes ("size mismatch"). Whitespace around keys and values is dropped,
// so CR-LF header lines read as LF lines (the magic line itself must end in a bare LF, as Gwyddion's detector
// requires); blank header lines are skipped.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "afmkit/scan/height_map.hpp"

namespace afmkit::scan {

inline constexpr std::string_view gsf_magic = "Gwyddion Simple Field 1.0\n";

/// A GSF file read: the map (x/y in metres), its Title ("" when absent) and the other header fields in file order.
struct GsfField {
  HeightMap map;
  std::string title;
  std::vector<std::pair<std::string, std::string>> extra;
};

/// The bytes of the GSF file of `map` (invalid pixels replaced by the mean of the valid ones). Header: XRes, YRes,
/// XReal, YReal, XOffset, YOffset (shortest decimal text that reads back to the same double), XYUnits = m, ZUnits
/// (unless z_unit is empty), Title (unless empty). InvalidParameter "title" for a title with a control character
/// or a leading / trailing blank; "data" for a valid value beyond the float32 range (|z| > 3.4028235e38).
std::string format_gsf(const HeightMap& map, const std::string& title = "");
/// The bytes of the mask file of `map`: same grid, 1 valid / 0 invalid, no ZUnits, Title "<title> validity mask".
std::string format_gsf_mask(const HeightMap& map, const std::string& title = "");
/// "<dir>/<stem>_mask<extension>" for "<dir>/<stem><extension>" (extension ".gsf" when there is none).
std::string gsf_mask_path(const std::string& path);

/// Writes format_gsf(map, title) to `path` atomically and, when the map has a mask, format_gsf_mask to
/// gsf_mask_path(path) (the two committed as one set: both or neither, io::OutputSet). Returns the
/// paths written. InputError on an I/O failure.
std::vector<std::string> write_gsf(const std::string& path, const HeightMap& map, const std::string& title = "");

/// The GSF file held in `bytes`; `origin` names it in messages.
GsfField parse_gsf(std::string_view bytes, const std::string& origin);
/// The data file `bytes` with the mask file `mask_bytes` applied: a pixel is valid when the mask holds 1 there and
/// the value is finite. InputError naming `mask_origin` when the mask's XRes / YRes differ from the data's or a
/// mask value is not 0 or 1.
GsfField parse_gsf_with_mask(std::string_view bytes, const std::string& origin, std::string_view mask_bytes,
                             const std::string& mask_origin);
/// The GSF file at `path` (at most 2 GiB). InputError when it cannot be read or breaks a rule above.
GsfField read_gsf(const std::string& path);
/// The GSF file at `path` with the mask file at `mask_path` (write_gsf's pair: mask_path = gsf_mask_path(path)).
GsfField read_gsf_with_mask(const std::string& path, const std::string& mask_path);

}  // namespace afmkit::scan
