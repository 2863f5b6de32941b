#pragma once
// The measured curve a reconstruction reads (docs/reconstruction.md#input): a CSV table with a header naming each
// column and its unit, as the project's other readers take them.
//   FM: distance + frequency shift, e.g. `distance (nm), frequency shift (Hz)`
//   AM: separation + amplitude + phase, e.g. `separation (nm), amplitude (nm), phase (deg)`
// Columns are recognised by their first word (case-insensitive): distance / separation / z / gap / height (length),
// frequency / df / delta (frequency shift), amplitude, phase. Units "(u)", "[u]" or a "_u" suffix: lengths nm, pm,
// A, Å, um, µm, m; frequencies mHz, Hz, kHz; phase deg, °, rad. Separator: ';' if the header has one, else ',',
// else tab, else blanks. '#' lines are comments. Values are converted to SI (m, Hz, rad).
// Errors (InputError "<file>:<line>: column <n> (<name>): …"): no header, a missing column or unit, a cell that
// is not a finite number, a missing cell, a distance that is not strictly monotone, fewer than 5 rows.
#include <string>
#include <string_view>
#include <vector>

namespace afmkit::spectroscopy {

struct MeasuredCurve {
  bool frequency_modulation = false;  ///< FM (distance, Δf) or AM (separation, amplitude, phase)
  std::vector<double> distance;         ///< [m]
  std::vector<double> frequency_shift;  ///< [Hz] (FM)
  std::vector<double> amplitude;        ///< [m] (AM)
  std::vector<double> phase;            ///< [rad] (AM), as in the file (the phase convention is checked later)
  std::vector<int> lines;               ///< the file line of each row (messages)
};

MeasuredCurve parse_measured_curve(std::string_view text, const std::string& origin);
MeasuredCurve read_measured_curve(const std::string& path);

}  // namespace afmkit::spectroscopy
