#pragma once
// A measured force curve as an instrument records it, before any preparation (docs/spectroscopy.md):
// segments (approach, retract, pauses) of channels sampled together, in SI units, with the calibration the file
// carries. The readers (read_curves.hpp) produce it from text exports and native files; spectroscopy::prepare
// turns it into a force–distance law.
//
// Conventions (one for every reader):
//   * height z [m]: the piezo (cantilever base) position, increasing AWAY from the sample. Instruments that record
//     the extension towards the sample (Asylum's ZSnsr, JPK's "height" on some set-ups) are converted by the reader.
//   * deflection d [m]: the tip's displacement relative to the cantilever at rest, positive AWAY from the sample,
//     so that the force F = k·d is positive when repulsive (the project's sign convention, docs/conventions.md).
//     Tip–sample distance = z + d (up to the contact point's offset).
//   * deflection_volts [V]: the photodetector signal when the file has no calibrated deflection; d = InvOLS · V.
//   * force [N]: when the file (or its vendor software) already gives it; positive repulsive.
//   * time [s]: from the start of the curve, when the file has it.
// A channel the file does not have is an empty vector; the channels a segment has all have the same length.
// Values are as measured: a reader never smooths, drops or reorders samples (it may drop NaN padding at a
// segment's end, which instruments write to equalise lengths, and says so in `notes`).
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace afmkit::io::curves {

/// What a segment is, as the file labels it (or as the reader infers it from the height's direction).
enum class SegmentKind { approach, retract, pause, unknown };

/// "approach", "retract", "pause", "unknown".
const char* to_string(SegmentKind kind);

/// One segment of a force curve: channels sampled together (SI units, conventions above).
struct Segment {
  SegmentKind kind = SegmentKind::unknown;
  std::vector<double> height;            ///< z [m], increasing away from the sample
  std::vector<double> deflection;        ///< d [m], positive away from the sample (repulsive)
  std::vector<double> deflection_volts;  ///< photodetector signal [V]
  std::vector<double> force;             ///< F [N], positive repulsive
  std::vector<double> time;              ///< t [s]
  /// The number of samples (the length of every non-empty channel).
  std::size_t size() const;
};

/// Calibration and context the file carries; NaN (or empty) where the file does not say.
struct CurveMetadata {
  double spring_constant = std::numeric_limits<double>::quiet_NaN();      ///< k [N/m]
  double invols = std::numeric_limits<double>::quiet_NaN();               ///< inverse optical lever sensitivity [m/V]
  double resonance_frequency = std::numeric_limits<double>::quiet_NaN();  ///< f0 [Hz] (thermal tune)
  double quality_factor = std::numeric_limits<double>::quiet_NaN();       ///< Q (thermal tune)
  std::string instrument;  ///< e.g. "JPK", "Asylum MFP-3D", "NT-MDT", "AFM Workshop", "Bruker Nanoscope", "text"
  std::string format;      ///< the reader that read it, e.g. "jpk-force", "ibw", "text"
};

/// One force curve: its segments in recording order, and the file's calibration.
struct RawCurve {
  std::vector<Segment> segments;
  CurveMetadata metadata;
  std::string origin;               ///< file name (and curve index inside it), used in messages
  std::vector<std::string> notes;   ///< what the reader did that a user should know (dropped padding, …)
};

}  // namespace afmkit::io::curves
