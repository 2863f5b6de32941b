// The reconstructed force as a table-law file (reconstruct_law.hpp).
#include "afmkit/spectroscopy/reconstruct_law.hpp"

#include <fmt/format.h>

namespace afmkit::spectroscopy {

impact::ForceCurve force_curve_from_si(const std::vector<double>& distance, const std::vector<double>& approach,
                                       const std::vector<double>& retract, const std::string& origin) {
  impact::ForceCurve c;
  c.origin = origin;
  for (std::size_t i = 0; i < distance.size(); ++i) {
    c.approach_gap.push_back(distance[i] * 1e9);
    c.approach_force.push_back(approach[i] * 1e9);
    c.retract_gap.push_back(distance[i] * 1e9);
    c.retract_force.push_back(retract[i] * 1e9);
  }
  return c;
}

std::string table_law_text(const impact::ForceCurve& curve, const std::string& comment) {
  std::string out = comment.empty() ? std::string() : "# " + comment + "\n";
  out += "distance (nm),approach force (nN),retract force (nN)\n";
  for (std::size_t i = 0; i < curve.approach_gap.size(); ++i)
    out += fmt::format("{:.17g},{:.17g},{:.17g}\n", curve.approach_gap[i], curve.approach_force[i],
                       curve.retract_force[i]);
  return out;
}

}  // namespace afmkit::spectroscopy
