#pragma once
// Reading measured force curves from instrument files (docs/curve-files.md lists the formats and presets).
// Every reader produces RawCurve values (raw_curve.hpp: SI units, one sign convention); bad input throws
// afmkit::InputError naming the file (and line, column or record where it applies).
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "afmkit/io/curves/raw_curve.hpp"

namespace afmkit::io::curves {

/// A column of a text export, chosen by name (case-insensitive match of the header cell, without its unit) or by
/// 1-based position; with the unit of its values when the header does not give one.
struct ColumnChoice {
  std::string name;    ///< header name; empty: not chosen by name
  int position = 0;    ///< 1-based column; 0: not chosen by position
  std::string unit;    ///< e.g. "nm", "um", "m", "V", "nN", "pN", "N", "s", "ms"; empty: from the header
  bool given() const { return !name.empty() || position > 0; }
};

/// How to read a file. Defaults read any supported file: the format from its content and extension, the columns
/// of a text export from its preset or header.
struct ReadOptions {
  /// "auto", or one of: "jpk-force", "ibw", "text", and the text presets "jpk-txt", "asylum-txt",
  /// "nanoscope-txt", "ntmdt-txt", "afmworkshop-csv".
  std::string format = "auto";
  /// Text exports: the columns (presets fill them). The binary formats use only the names: `height.name` picks a
  /// JPK channel ("height" for the piezo's; default the measured height) or an Igor wave column label (default
  /// "ZSnsr"); `deflection.name` and `force.name` pick Igor column labels ("Defl", "Force").
  ColumnChoice height, deflection, force, time, segment;
  /// Text exports that write the retract beside the approach (one row holds a sample of each): the retract's
  /// columns; when one is given, height/deflection/force above are the approach's. A retract deflection or force
  /// without a retract height shares the approach's height column (NT-MDT). (Addition to the lead's API.)
  ColumnChoice retract_height, retract_deflection, retract_force;
  /// Text exports: "auto", "tab", "semicolon", "comma", "blank"; and the decimal mark "auto", "point", "comma".
  std::string separator = "auto";
  std::string decimal = "auto";
  /// Which way the height column of a text export grows: "auto" (the preset's; for "text": away from the
  /// sample), "away" (a height), "towards" (an extension, e.g. Asylum's ZSnsr: the reader negates it).
  std::string height_direction = "auto";
  /// Calibration that overrides (or supplies) what the file says; NaN: take the file's.
  double spring_constant = std::numeric_limits<double>::quiet_NaN();  ///< k [N/m]
  double invols = std::numeric_limits<double>::quiet_NaN();           ///< [m/V]
};

/// Reads every curve of the file at `path` (a file may hold several repeated curves).
std::vector<RawCurve> read_curves(const std::string& path, const ReadOptions& options = {});

/// The same for the bytes of a file already in memory (`origin` names it in messages); `extension` (".jpk-force",
/// ".ibw", ".txt", …) helps the "auto" format.
std::vector<RawCurve> parse_curves(std::string_view bytes, const std::string& origin, const std::string& extension,
                                   const ReadOptions& options = {});

}  // namespace afmkit::io::curves
