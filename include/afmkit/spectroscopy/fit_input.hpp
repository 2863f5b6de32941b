#pragma once
// The measured AM-AFM curve file of `afmkit spectroscopy fit` (docs/fitting.md#input).
//
//   * UTF-8 text; lines whose first non-blank character is '#' are comments; blank lines are ignored; CR-LF accepted.
//   * The first other line is the header. Separator: ';' if the header has one, else ',', else a tab, else blanks.
//   * Columns (any order; others are refused): distance, amplitude, phase (optional), each with its unit written
//     "name (unit)", "name [unit]" or "name_unit":
//       distance: also "separation", "z", "height", "piezo"; unit m, mm, um, µm, nm, pm, A, Å
//       amplitude: also "amp"; unit m, mm, um, µm, nm, pm, A, Å
//       phase: also "phi"; unit rad or deg
//   * One row per distance: numbers with a decimal point (nan/inf refused), distances distinct.
//   * Errors: InputError "<file>:<line>:<column>: …" (column counted from 1 in characters of the line).
#include <string>
#include <string_view>

#include "afmkit/spectroscopy/fit.hpp"

namespace afmkit::spectroscopy {

/// Parses the text of an AM curve file (SI units out); `origin` names it in messages.
FitCurve parse_am_curve(std::string_view text, const std::string& origin);
/// Reads the file `path` (InputError naming it when it cannot be read).
FitCurve read_am_curve(const std::string& path);

}  // namespace afmkit::spectroscopy
