#pragma once
// afmkit spectroscopy prepare, shared by the command line and the Python module (afmkit.spectroscopy.prepare takes
// the curve as NumPy arrays instead of a file).
#include <string>
#include <vector>

#include "afmkit/io/curves/raw_curve.hpp"
#include "afmkit/io/params.hpp"
#include "command.hpp"

namespace afmkit::cli {

/// The parameters that say how to read the input file (not used when the curves are given as arrays).
const std::vector<std::string>& prepare_file_keys();

/// Prepares `curves` with the command's parameters `p` and writes / captures the outputs (the law table, its
/// sidecar, the plot), as `afmkit spectroscopy prepare` does after reading its file; `origin` names the input.
void run_prepare_curves(const io::ParamSet& p, const std::vector<io::curves::RawCurve>& curves, Captured* capture);

}  // namespace afmkit::cli
