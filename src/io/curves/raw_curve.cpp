#include "afmkit/io/curves/raw_curve.hpp"

#include <algorithm>

namespace afmkit::io::curves {

const char* to_string(SegmentKind kind) {
  switch (kind) {
    case SegmentKind::approach: return "approach";
    case SegmentKind::retract: return "retract";
    case SegmentKind::pause: return "pause";
    case SegmentKind::unknown: break;
  }
  return "unknown";
}

std::size_t Segment::size() const {
  return std::max({height.size(), deflection.size(), deflection_volts.size(), force.size(), time.size()});
}

}  // namespace afmkit::io::curves
