#pragma once
// The presets of the text reader (docs/curve-files.md#presets): which columns each instrument's text export has,
// their units and sign, where the segments are, which metadata lines carry the calibration. Internal.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "text_table.hpp"
#include "units.hpp"

namespace afmkit::io::curves::detail {

/// A header name a role accepts: exact (case-insensitive, with or without its unit), "*suffix" or "~substring";
/// with the unit its values have when the header does not say.
struct Candidate {
  std::string pattern;
  std::string unit;
};

/// One column role (height, deflection, ...) of a preset.
struct Role {
  const char* name = "";
  std::vector<Candidate> candidates;  ///< tried in order against the header
  int default_position = 0;           ///< 1-based column when the file has no header row
  std::string default_unit;           ///< with default_position
  std::vector<Quantity> quantities;   ///< what its unit may measure
  bool required = false;
  std::string expected;               ///< for messages: "'Extend Z-Sense(nm)'"
};

/// A calibration in a metadata line "key: value".
struct MetadataKey {
  enum Target { spring_constant, invols } target;
  std::string key;
  double scale = 1.0;          ///< to SI
  bool reciprocal = false;     ///< the SI value is 1 / (value * scale)
  std::optional<double> ignore_value;  ///< a placeholder the instrument writes when it has no calibration
};

struct Preset {
  std::string format;
  std::string instrument;
  double height_sign = 1.0;     ///< -1: the file's height column grows towards the sample
  bool side_by_side = false;    ///< approach and retract in separate columns of the same rows
  bool require_retract = false;
  bool comment_header = false;  ///< column names and units in "# columns:" / "# units:" comments (JPK)
  bool comment_segments = false;  ///< segments labelled by "# segment: extend" comments (JPK)
  TextSyntax syntax;
  Role height, deflection, force, time, segment, retract_height, retract_deflection, retract_force, retract_time;
  std::vector<MetadataKey> metadata;
  std::string signature;        ///< for messages: what the file must look like
};

/// The preset named `format` ("text" or a preset), or nullptr.
const Preset* find_preset(const std::string& format);

/// "text, jpk-txt, asylum-txt, nanoscope-txt, ntmdt-txt, afmworkshop-csv".
const char* text_format_names();

/// InputError naming `origin` when the table does not look like a file of the preset's instrument.
void check_signature(const Preset& preset, const TextTable& table, const std::string& origin);

/// Column names and units given in comments ("# columns: height vDeflection", "# units: m N"), JPK style.
struct CommentHeader {
  std::vector<std::string> names, units;
  int line = 0;
};

/// The comment header of `table`, or nullopt when it has none. InputError when the segments' "columns:" comments
/// differ or do not match the number of columns of the data.
std::optional<CommentHeader> comment_header(const TextTable& table, const std::string& origin);

/// The label of a "segment: extend" comment, or nullopt.
std::optional<std::string> segment_label(std::string_view comment);

}  // namespace afmkit::io::curves::detail
