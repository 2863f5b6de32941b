#pragma once
// The measured curve file of `afmkit spectroscopy fit` (docs/fitting.md#input): an AM-AFM amplitude/phase or an
// FM-AFM frequency-shift (/dissipation) curve, told apart by its columns.
//
//   * UTF-8 text; lines whose first non-blank character is '#' are comments; blank lines are ignored; CR-LF accepted.
//   * The first other line is the header. Separator: ';' if the header has one, else ',', else a tab, else blanks.
//   * Columns (any order; others are refused), each with its unit written "name (unit)", "name [unit]" or
//     "name_unit": AM distance, amplitude, phase (optional); FM distance, frequency shift, dissipation (optional):
//       distance: also "separation", "z", "height", "piezo"; unit m, mm, um, µm, nm, pm, A, Å
//       amplitude: also "amp"; unit m, mm, um, µm, nm, pm, A, Å
//       phase: also "phi"; unit rad or deg
//       frequency shift: also "frequency_shift", "df", "delta f", "Δf"; unit Hz, mHz, kHz (MHz as written)
//       dissipation: also "energy", "dissipated energy"; unit J, aJ, zJ, eV, meV (energy per oscillation cycle)
//     A frequency shift column makes the file an FM curve, an amplitude column an AM curve (both: refused).
//   * One row per distance: numbers with a decimal point (nan/inf refused), distances distinct.
//   * Errors: InputError "<file>:<line>:<column>: …" (column counted from 1 in characters of the line).
#include <string>
#include <string_view>

#include "afmkit/spectroscopy/fit.hpp"

namespace afmkit::spectroscopy {

/// What a curve file holds: an AM curve (mode am: `am` filled) or an FM curve (mode fm: `fm` filled), SI units.
struct FitCurveFile {
  FitMode mode = FitMode::am;
  FitCurve am;
  FmFitCurve fm;
};

/// Parses the text of a curve file (SI units out); `origin` names it in messages.
FitCurveFile parse_fit_curve(std::string_view text, const std::string& origin);
/// Reads the file `path` (InputError naming it when it cannot be read).
FitCurveFile read_fit_curve(const std::string& path);
/// As parse_fit_curve / read_fit_curve, an FM file refused (InputError).
FitCurve parse_am_curve(std::string_view text, const std::string& origin);
FitCurve read_am_curve(const std::string& path);

}  // namespace afmkit::spectroscopy
