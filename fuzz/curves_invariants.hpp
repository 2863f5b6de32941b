#pragma once
// Shared by the io_curves fuzz targets: the invariants every reader's output obeys (raw_curve.hpp), checked on
// each input the reader accepts; any other exception than afmkit::InputError escapes and fails the run.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/read_curves.hpp"

namespace curves_fuzz {

inline bool same(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// Parses `bytes` twice (the result must not depend on anything but the bytes) and checks the curves.
inline void check(const std::string& bytes, const std::string& extension, const afmkit::io::curves::ReadOptions& o) {
  namespace ac = afmkit::io::curves;
  std::vector<ac::RawCurve> curves;
  try {
    curves = ac::parse_curves(bytes, "fuzz", extension, o);
  } catch (const afmkit::InputError&) {
    return;
  }
  const std::vector<ac::RawCurve> again = ac::parse_curves(bytes, "fuzz", extension, o);
  if (curves.empty() || again.size() != curves.size()) std::abort();
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const ac::RawCurve& curve = curves[c];
    if (curve.segments.empty() || curve.segments.size() != again[c].segments.size()) std::abort();
    for (double v : {curve.metadata.spring_constant, curve.metadata.invols, curve.metadata.resonance_frequency,
                     curve.metadata.quality_factor})
      if (!std::isnan(v) && !(std::isfinite(v) && v > 0)) std::abort();
    for (std::size_t s = 0; s < curve.segments.size(); ++s) {
      const ac::Segment& seg = curve.segments[s];
      const ac::Segment& twin = again[c].segments[s];
      const std::size_t n = seg.size();
      if (n == 0 || seg.kind != twin.kind) std::abort();
      for (const auto* ch : {&seg.height, &seg.deflection, &seg.deflection_volts, &seg.force, &seg.time}) {
        if (!ch->empty() && ch->size() != n) std::abort();
        for (double v : *ch)
          if (!std::isfinite(v)) std::abort();
      }
      if (!same(seg.height, twin.height) || !same(seg.deflection, twin.deflection) ||
          !same(seg.deflection_volts, twin.deflection_volts) || !same(seg.force, twin.force) ||
          !same(seg.time, twin.time))
        std::abort();
    }
  }
}

}  // namespace curves_fuzz
