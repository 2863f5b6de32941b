#pragma once
// A recorded spiral: the samples a real rotational-scanning AFM logged (the sample spins on a spindle, the tip moves
// radially), read as a stream so that a recording of any length needs memory for one revolution only.
//
// CSV format (text, C-locale decimal numbers as io::parse_real reads them: "1.5", "-2e-9"; no nan / inf):
//   # optional comment lines (first non-blank character '#'), anywhere; blank lines are skipped too
//   time,angle,radius,deflection          a header line naming the columns, comma-separated, in any order
//   0,0,1e-05,1.2e-09                     one sample per line, as many cells as the header has columns
// Columns (names matched ignoring ASCII case and blanks around them; columns with other names are ignored, their
// cells are not read; cells are separated by commas, blanks around a cell are dropped; CR-LF line ends and a
// UTF-8 byte-order mark are accepted):
//   time        [s]    sample time, strictly increasing and uniformly sampled: every interval Δt within
//                      1e-3 · Δt0 of the first interval Δt0 = t1 − t0 (sample_rate() = 1 / Δt0)
//   radius      [m]    distance of the tip from the spindle axis, >= 0
//   deflection  [m]    cantilever deflection, in [−1, 1] m (far beyond any AFM signal; the bound keeps the
//                      filter's sums finite)
//   and exactly one of
//   angle       [rad]  spindle angle, wrapped (e.g. into [−π, π) or [0, 2π)) or already unwrapped. The reader
//                      unwraps it: a step below −π between two samples counts as one wrap (+2π); after that every
//                      step must be > 0 (a spindle turning backwards or standing still is an error). The first
//                      sample keeps its angle (the encoder's zero stays angle 0).
//   index      [0/1]  spindle index pulse. A rising edge — a sample reading 1 after a sample reading 0 — marks
//                      angle 0 of a revolution at the time of that sample (the first row cannot be an edge). Between
//                      two edges the angle grows linearly in time by 2π; the first edge is angle 0, the n-th edge
//                      2π·(n − 1). Samples before the first edge and after the last edge are dropped (counted by
//                      dropped_samples()); the sample at the last edge itself is kept (angle 2π · revolutions).
//                      Discretisation: the pulse is seen at the first sample at or after the true index time, so a
//                      constant-speed spindle gives angles that lag the true angle by [0, Ω·Δt) (Ω·Δt = one
//                      sample's rotation), and rotation_frequency() has a relative error below Δt / T_revolution.
// At least two full revolutions are needed: angle mode, an advance of 4π from the first sample; index mode, three
// rising edges.
//
// Errors: InputError "<origin>:<line>: …" naming the column where there is one:
//   no header line ("<origin>: …"); a missing or duplicate column; both or neither of angle / index; a row with
//   another number of cells than the header has columns (ragged row); a cell that is not a finite number; time not
//   strictly increasing; non-uniform sampling; radius < 0; an index value other than 0 / 1; the angle not increasing
//   after unwrapping; fewer than two revolutions (at the end of the data, the line of the last row); a line longer
//   than 1 MiB; a revolution (the look-ahead) longer than 2^24 samples; a sampling interval so small or large that
//   1 / Δt or Ω is not a finite positive number.
// Streaming: a bad row far into the file is reported only when next() reaches it, so samples before it may already
// have been returned; a consumer treats an InputError from next() as failing the whole recording.
#include <iosfwd>
#include <memory>
#include <string>

namespace afmkit::scan {

/// One sample of a recorded spiral.
struct SpiralSample {
  double time;        ///< [s]
  double angle;       ///< spindle angle, unwrapped [rad], strictly increasing
  double radius;      ///< [m], >= 0
  double deflection;  ///< [m]
};

/// Reads a recorded spiral CSV (format above) sample by sample. Memory: one revolution of look-ahead.
class RecordedSpiralReader {
 public:
  /// Opens the file at `path`; messages name it as the origin. InputError "<path>: …" if it cannot be read.
  explicit RecordedSpiralReader(const std::string& path);
  /// Reads from `in` (tests, fuzzing, pipes); `origin` names it in messages.
  RecordedSpiralReader(std::unique_ptr<std::istream> in, std::string origin);
  ~RecordedSpiralReader();
  RecordedSpiralReader(RecordedSpiralReader&&) noexcept;
  RecordedSpiralReader& operator=(RecordedSpiralReader&&) noexcept;
  RecordedSpiralReader(const RecordedSpiralReader&) = delete;
  RecordedSpiralReader& operator=(const RecordedSpiralReader&) = delete;

  /// The next sample into `sample`; false at the end of the data (then `sample` is left unchanged). InputError as
  /// listed above. After an InputError the reader stays failed: further calls throw the same error again.
  bool next(SpiralSample& sample);

  /// 1 / Δt0 [Hz], Δt0 the first sampling interval (known after construction).
  double sample_rate() const;
  /// Ω [rad/s] of the first revolution: 2π over the time the angle took to advance 2π from the first sample (angle
  /// mode; the crossing time interpolated linearly between the two samples around it) or between the first two
  /// index edges (index mode). Known after construction.
  double rotation_frequency() const;
  /// Index mode: samples dropped before the first edge (known after construction) plus those after the last edge
  /// (added when the end of the data is reached). Angle mode: 0.
  long dropped_samples() const;
  /// Whether the recording has an index column (else an angle column).
  bool uses_index_pulse() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace afmkit::scan
