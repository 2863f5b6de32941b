// libFuzzer target: the force-curve reader and the table law (afmkit/impact/laws/table_law.hpp). Input = the text
// of a force-curve file. Invariants: the text is either rejected with afmkit::InputError (parse) /
// afmkit::InvalidParameter (law) — whose messages start with the origin — or it gives two branches of ≥ 4 finite
// points with strictly ascending gaps, and a law that reproduces every knot, never leaves the range of the two
// knots around any gap inside the table (PCHIP is shape-preserving), is 0 above each branch and continues
// linearly below it. Nothing else (no crash, no other exception, no sanitizer report).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/laws/table_law.hpp"

namespace {

void check_branch(const std::vector<double>& gap, const std::vector<double>& force) {
  if (gap.size() < 4 || gap.size() != force.size()) std::abort();
  for (std::size_t i = 0; i < gap.size(); ++i) {
    if (!std::isfinite(gap[i]) || !std::isfinite(force[i])) std::abort();
    if (i > 0 && !(gap[i] > gap[i - 1])) std::abort();
  }
}

void check_law(const afmkit::impact::TableLaw& law, bool approach, const std::vector<double>& gap,
               const std::vector<double>& force) {
  auto f = [&](double d) { return approach ? law.approach(d) : law.departure(d); };
  const std::size_t n = gap.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (f(gap[i]) != force[i]) std::abort();  // exact at the knots
    if (i + 1 == n) break;
    const double lo = std::min(force[i], force[i + 1]), hi = std::max(force[i], force[i + 1]);
    const double tol = 1e-12 * std::max(std::abs(lo), std::abs(hi));
    for (double s : {0.25, 0.5, 0.75}) {
      const double d = gap[i] + s * (gap[i + 1] - gap[i]);
      const double v = f(d);
      if (!(v >= lo - tol && v <= hi + tol)) std::abort();  // no overshoot (also catches NaN)
    }
  }
  const double above = gap[n - 1] + std::max(1.0, std::abs(gap[n - 1]));
  if (std::isfinite(above) && f(above) != 0.0) std::abort();
  // below the table: a straight line through the first knot
  const double width = gap[n - 1] - gap[0];
  const double b1 = f(gap[0] - 0.5 * width), b2 = f(gap[0] - width);
  if (std::isfinite(b1) && std::isfinite(b2)) {
    const double second = (b2 - force[0]) - 2.0 * (b1 - force[0]);  // 0 for a line
    if (std::abs(second) > 1e-9 * (std::abs(b2) + std::abs(b1) + std::abs(force[0]))) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  afmkit::impact::ForceCurve curve;
  try {
    curve = afmkit::impact::parse_force_curve(text, "fuzz.csv");
  } catch (const afmkit::InputError& e) {
    if (std::string_view(e.what()).rfind("fuzz.csv:", 0) != 0) std::abort();
    return 0;
  }
  check_branch(curve.approach_gap, curve.approach_force);
  check_branch(curve.retract_gap, curve.retract_force);
  try {
    const afmkit::impact::TableLaw law(curve);
    check_law(law, true, curve.approach_gap, curve.approach_force);
    check_law(law, false, curve.retract_gap, curve.retract_force);
    // the switching gaps: sorted and distinct; both tables' ends, and at most the retract's kink below its table
    // (table_law.hpp) and the contact and release gaps of the contact-aware default (docs/force-laws.md)
    const std::vector<double> gaps = law.switching_gaps();
    if (gaps.empty() || gaps.size() > 5 || !std::is_sorted(gaps.begin(), gaps.end()) ||
        std::adjacent_find(gaps.begin(), gaps.end()) != gaps.end())
      std::abort();
    for (double end : {curve.approach_gap.back(), curve.retract_gap.back()})
      if (std::find(gaps.begin(), gaps.end(), end) == gaps.end()) std::abort();
    (void)law.hysteresis_area(std::min(curve.approach_gap[0], curve.retract_gap[0]), gaps.back());
    law.require_dissipative();
  } catch (const afmkit::InvalidParameter& e) {
    if (e.parameter() != "force_curve") std::abort();
    return 0;
  }
  return 0;
}
