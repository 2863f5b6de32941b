#pragma once
// The reconstructed force as a table law (impact/laws/table_law.hpp): distance (nm), approach force (nN), retract
// force (nN), the file `afmkit tapping orbit --law table --force-curve FILE` reads.
#include <string>
#include <vector>

#include "afmkit/impact/laws/table_law.hpp"

namespace afmkit::spectroscopy {

/// A force curve from SI arrays: distance [m] ascending, approach and retract force [N] (converted to nm, nN).
impact::ForceCurve force_curve_from_si(const std::vector<double>& distance, const std::vector<double>& approach,
                                       const std::vector<double>& retract, const std::string& origin);

/// The table-law file text (3-column layout; a '#' comment line first unless `comment` is empty): read back by
/// impact::parse_force_curve.
std::string table_law_text(const impact::ForceCurve& curve, const std::string& comment);

}  // namespace afmkit::spectroscopy
