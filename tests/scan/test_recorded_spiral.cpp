// Recorded spiral CSV reader, against hand-built CSV text: an ideal spiral of known rotation frequency Ω and
// sample rate f_s written with %.17g (so each cell reads back to the very double written), in the three angle
// encodings (unwrapped angle, wrapped angle, index pulse), and one file per error rule.
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/recorded_spiral.hpp"
#include "scan_test_dir.hpp"

using afmkit::InputError;
using afmkit::scan::RecordedSpiralReader;
using afmkit::scan::SpiralSample;

namespace {

constexpr double two_pi = 6.283185307179586;

std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// An ideal spiral: sample k at t_k = t0 + k / f_s, angle θ_k = θ0 + Ω · k / f_s (unwrapped), radius moving in by
/// one pitch per revolution, deflection a ripple.
struct Spiral {
  double omega = two_pi * 7.3;  // Ω [rad/s]: 7.3 revolutions per second
  double rate = 1000.0;         // f_s [Hz]: 136.99 samples per revolution (not an integer)
  double t0 = 0.25;
  double theta0 = 1.0;
  double r0 = 20e-6;
  double pitch = 1.5e-6;  // radius step per revolution [m]
  long n = 500;           // 3.65 revolutions

  double time(long k) const { return t0 + static_cast<double>(k) / rate; }
  double angle(long k) const { return theta0 + omega * (static_cast<double>(k) / rate); }
  double radius(long k) const { return r0 - pitch * (angle(k) - theta0) / two_pi; }
  double deflection(long k) const { return 2e-9 * std::sin(5.0 * angle(k)); }
};

enum class Encoding { unwrapped, wrapped_symmetric, wrapped_positive, index };

/// The CSV of `s`: a comment, a header with the columns in an unusual order plus an ignored text column.
std::string csv(const Spiral& s, Encoding e, double pulse_width = 0.3) {
  const bool index = e == Encoding::index;
  std::string out = "# recorded on the bench\n";
  out += std::string("deflection,radius,note,") + (index ? "index" : "angle") + ",time\n";
  for (long k = 0; k < s.n; ++k) {
    const double theta = s.angle(k);
    std::string angle_cell;
    switch (e) {
      case Encoding::unwrapped: angle_cell = g17(theta); break;
      case Encoding::wrapped_symmetric: angle_cell = g17(std::remainder(theta, two_pi)); break;  // [−π, π]
      case Encoding::wrapped_positive: angle_cell = g17(std::fmod(theta, two_pi)); break;        // [0, 2π)
      case Encoding::index: angle_cell = std::fmod(theta, two_pi) < pulse_width ? "1" : "0"; break;
    }
    out += g17(s.deflection(k)) + "," + g17(s.radius(k)) + ",ok," + angle_cell + "," + g17(s.time(k)) + "\n";
  }
  return out;
}

RecordedSpiralReader reader_of(const std::string& text, const std::string& origin = "rec.csv") {
  return RecordedSpiralReader(std::make_unique<std::istringstream>(text), origin);
}

std::vector<SpiralSample> read_all(RecordedSpiralReader& r) {
  std::vector<SpiralSample> out;
  SpiralSample s{};
  while (r.next(s)) out.push_back(s);
  return out;
}

/// The message of the InputError raised while reading `text` to the end ("" when none).
std::string spiral_error_of(const std::string& text) {
  try {
    auto r = reader_of(text);
    read_all(r);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// A valid 4-column angle-mode file: header then `rows` of (t, angle, radius, deflection) with Δt = 0.01 s and
/// Δθ = 0.5 rad (12.6 samples per revolution).
std::string good_rows(long rows, const std::string& header = "time,angle,radius,deflection\n") {
  std::string out = header;
  for (long k = 0; k < rows; ++k)
    out += g17(0.01 * static_cast<double>(k)) + "," + g17(0.5 * static_cast<double>(k)) + ",1e-06,0\n";
  return out;
}

}  // namespace

TEST(RecordedSpiral, IdealSpiralWithUnwrappedAngleReadsBackExactly) {
  const Spiral s;
  auto r = reader_of(csv(s, Encoding::unwrapped));
  EXPECT_FALSE(r.uses_index_pulse());
  EXPECT_NEAR(r.sample_rate(), s.rate, 1e-9 * s.rate);  // 1 / (t1 − t0) of two printed times
  EXPECT_NEAR(r.rotation_frequency(), s.omega, 1e-12 * s.omega);
  const auto samples = read_all(r);
  ASSERT_EQ(samples.size(), static_cast<std::size_t>(s.n));
  EXPECT_EQ(r.dropped_samples(), 0);
  for (long k = 0; k < s.n; ++k) {
    const SpiralSample& x = samples[static_cast<std::size_t>(k)];
    EXPECT_NEAR(x.time, s.time(k), 1e-12);
    EXPECT_NEAR(x.angle, s.angle(k), 1e-12);
    EXPECT_NEAR(x.radius, s.radius(k), 1e-12 * s.r0);
    EXPECT_NEAR(x.deflection, s.deflection(k), 1e-12 * 2e-9);
  }
}

TEST(RecordedSpiral, WrappedAnglesAreUnwrapped) {
  Spiral s;
  s.theta0 = -2.5;  // starts in the first half turn, so both wrappings have a different first value
  for (Encoding e : {Encoding::wrapped_symmetric, Encoding::wrapped_positive}) {
    SCOPED_TRACE(e == Encoding::wrapped_symmetric ? "[-pi, pi]" : "[0, 2pi)");
    auto r = reader_of(csv(s, e));
    EXPECT_NEAR(r.rotation_frequency(), s.omega, 1e-12 * s.omega);
    const auto samples = read_all(r);
    ASSERT_EQ(samples.size(), static_cast<std::size_t>(s.n));
    // The reader keeps the first value (−2.5 in both: fmod takes the sign of its argument) and adds 2π per wrap.
    for (long k = 0; k < s.n; ++k)
      EXPECT_NEAR(samples[static_cast<std::size_t>(k)].angle, s.angle(k), 1e-12) << "sample " << k;
  }
}

TEST(RecordedSpiral, WrappedIntoZeroToTwoPiKeepsTheFirstValue) {
  Spiral s;
  s.theta0 = 5.0;  // fmod(5 + …, 2π) ∈ [0, 2π): first value 5, wraps to ~0 after 0.28 rad
  auto r = reader_of(csv(s, Encoding::wrapped_positive));
  const auto samples = read_all(r);
  ASSERT_EQ(samples.size(), static_cast<std::size_t>(s.n));
  for (long k = 0; k < s.n; ++k) EXPECT_NEAR(samples[static_cast<std::size_t>(k)].angle, s.angle(k), 1e-12);
}

TEST(RecordedSpiral, IndexPulseGivesTheSameAnglesToOneSampleOfRotation) {
  // Discretisation: the pulse for angle 2πn is seen at the first sample with θ ≥ 2πn, i.e. up to one sample late,
  // so at every edge the read angle lags the true one by [0, Ω/f_s); between edges both are linear in time, so the
  // lag stays in [0, Ω/f_s) everywhere. Angle 0 is the first edge: true angle 2π (θ0 = 1 < 2π).
  const Spiral s;
  const double step = s.omega / s.rate;  // rotation per sample: 0.0459 rad
  auto r = reader_of(csv(s, Encoding::index));
  EXPECT_TRUE(r.uses_index_pulse());
  EXPECT_NEAR(r.sample_rate(), s.rate, 1e-9 * s.rate);
  const double period = two_pi / s.omega;
  const double dt = 1.0 / s.rate;
  EXPECT_NEAR(r.rotation_frequency(), s.omega, s.omega * dt / (period - dt));

  // Independent count of the samples the edges keep: from the first with θ ≥ 2π to the first with θ ≥ 2π·M,
  // M the last whole turn reached.
  long first = 0;
  while (s.angle(first) < two_pi) ++first;
  const long turns = static_cast<long>(std::floor(s.angle(s.n - 1) / two_pi));
  long last = first;
  while (s.angle(last) < two_pi * static_cast<double>(turns)) ++last;
  EXPECT_EQ(r.dropped_samples(), first);  // known after construction
  const auto samples = read_all(r);
  ASSERT_EQ(samples.size(), static_cast<std::size_t>(last - first + 1));
  EXPECT_EQ(r.dropped_samples(), first + (s.n - 1 - last));

  double largest_lag = 0.0;
  for (std::size_t m = 0; m < samples.size(); ++m) {
    const long k = first + static_cast<long>(m);
    EXPECT_EQ(samples[m].time, s.time(k));
    EXPECT_EQ(samples[m].radius, std::stod(g17(s.radius(k))));
    const double lag = (s.angle(k) - two_pi) - samples[m].angle;
    EXPECT_GE(lag, -1e-12) << "sample " << k;
    EXPECT_LT(lag, step + 1e-12) << "sample " << k;
    largest_lag = std::max(largest_lag, lag);
  }
  EXPECT_GT(largest_lag, 0.3 * step);  // the bound is not vacuous: the discretisation shows
  EXPECT_EQ(samples.front().angle, 0.0);
  EXPECT_EQ(samples.back().angle, two_pi * static_cast<double>(turns - 1));
}

TEST(RecordedSpiral, IndexHighAtTheStartIsNotAnEdge) {
  // Rows: index 1 1 0 0 1 0 0 0 1 0 0 1 0 → edges at rows 4, 8, 11 (0-based): 4 dropped before, 1 after.
  const int index[] = {1, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0};
  std::string text = "time,index,radius,deflection\n";
  for (int k = 0; k < 13; ++k) text += std::to_string(k) + "," + std::to_string(index[k]) + ",1,0\n";
  auto r = reader_of(text);
  EXPECT_EQ(r.dropped_samples(), 4);
  EXPECT_DOUBLE_EQ(r.rotation_frequency(), two_pi / 4.0);  // edges at t = 4 and 8
  const auto samples = read_all(r);
  ASSERT_EQ(samples.size(), 8u);  // rows 4 … 11
  for (std::size_t m = 0; m < 8; ++m) {
    // revolution 1: 4 samples a quarter turn apart; revolution 2: 3 samples a third of a turn apart; last edge
    const double turns = m < 4 ? static_cast<double>(m) / 4.0 : 1.0 + (static_cast<double>(m) - 4.0) / 3.0;
    EXPECT_NEAR(samples[m].angle, two_pi * turns, 1e-14) << m;
    EXPECT_EQ(samples[m].time, 4.0 + static_cast<double>(m));
  }
  EXPECT_EQ(r.dropped_samples(), 5);
}

TEST(RecordedSpiral, LookAheadIsOneRevolution) {
  // The stream is read only as far as needed: after construction up to the second edge, later at most one
  // revolution (plus a line) beyond the sample returned.
  Spiral s;
  s.n = 3000;  // 21.9 revolutions
  s.pitch = 0.5e-6;
  const std::string text = csv(s, Encoding::index);
  auto stream = std::make_unique<std::istringstream>(text);
  std::istringstream* raw = stream.get();
  RecordedSpiralReader r(std::move(stream), "rec.csv");
  // Byte offset of the start of each data row (line 3 on).
  std::vector<std::size_t> row_start;
  for (std::size_t at = text.find('\n', text.find('\n') + 1) + 1; at < text.size(); at = text.find('\n', at) + 1)
    row_start.push_back(at);
  ASSERT_EQ(row_start.size(), static_cast<std::size_t>(s.n));
  const auto samples_per_turn = static_cast<std::size_t>(std::ceil(s.rate * two_pi / s.omega));
  const auto first = static_cast<std::size_t>(r.dropped_samples());
  EXPECT_LE(static_cast<std::size_t>(raw->tellg()), row_start[first + samples_per_turn + 1]);
  SpiralSample x{};
  for (std::size_t m = 0; r.next(x); ++m) {
    const std::size_t row = first + m;
    const std::streamoff at = raw->tellg();
    const std::size_t position = at < 0 ? text.size() : static_cast<std::size_t>(at);
    if (row + samples_per_turn + 1 < row_start.size()) {
      ASSERT_LE(position, row_start[row + samples_per_turn + 1]) << "sample " << m;
    }
  }
}

TEST(RecordedSpiral, CommentsBlankLinesCrLfBomAndHeaderCase) {
  std::string text = "\xEF\xBB\xBF# spindle log\r\n\r\n  Time , ANGLE,Radius,Deflection ,extra\r\n";
  for (int k = 0; k < 30; ++k) {
    text += g17(0.1 * k) + " , " + g17(0.5 * k) + ",\t2e-6,1e-9, x\r\n";
    if (k == 10) text += "# a comment between rows\r\n   \r\n";
  }
  auto r = reader_of(text);
  const auto samples = read_all(r);
  ASSERT_EQ(samples.size(), 30u);
  EXPECT_EQ(samples[29].angle, 14.5);
  EXPECT_EQ(samples[29].time, 0.1 * 29);
  EXPECT_EQ(samples[3].radius, 2e-6);
  EXPECT_NEAR(r.rotation_frequency(), 5.0, 1e-12);  // 0.5 rad per 0.1 s
  EXPECT_NEAR(r.sample_rate(), 10.0, 1e-12);
}

TEST(RecordedSpiral, HeaderErrorsNameLineAndColumn) {
  EXPECT_EQ(spiral_error_of(""), "rec.csv: no header line: a recorded spiral starts with a line naming its columns "
                          "(time, radius, deflection and angle or index)");
  EXPECT_EQ(spiral_error_of("# only a comment\n\n"), spiral_error_of(""));
  EXPECT_NE(spiral_error_of("0,1,2,3\n").find("rec.csv:1: the first line holds numbers, not column names"),
            std::string::npos);
  EXPECT_EQ(spiral_error_of("# c\ntime,angle,deflection\n"),
            "rec.csv:2: missing column 'radius' (the header must name time, radius, deflection and one of angle / "
            "index)");
  EXPECT_EQ(spiral_error_of("angle,radius,deflection\n").substr(0, 36), "rec.csv:1: missing column 'time' (th");
  EXPECT_EQ(spiral_error_of("time,angle,radius,TIME,deflection\n"),
            "rec.csv:1: duplicate column 'time' (columns 1 and 4 of the header)");
  EXPECT_EQ(spiral_error_of("time,angle,radius,deflection,index\n"),
            "rec.csv:1: both an 'angle' column (2) and an 'index' column (5): give exactly one");
  EXPECT_EQ(spiral_error_of("time,radius,deflection,position\n"),
            "rec.csv:1: neither an 'angle' nor an 'index' column: give exactly one (angle [rad] or index pulse 0/1)");
  EXPECT_EQ(spiral_error_of("time,angle,radius,deflection\n# nothing\n"),
            "rec.csv:1: no data rows after the header: a recorded spiral needs at least two revolutions");
}

TEST(RecordedSpiral, CellErrorsNameLineAndColumn) {
  const std::string h = "time,angle,radius,deflection\n";  // data row k is line k + 2
  EXPECT_EQ(spiral_error_of(h + "0,0,1e-6,0\n0.01,0.5,abc,0\n"), "rec.csv:3: column 'radius': 'abc' is not a finite number");
  EXPECT_EQ(spiral_error_of(h + "0,nan,1e-6,0\n"), "rec.csv:2: column 'angle': 'nan' is not a finite number");
  EXPECT_EQ(spiral_error_of(h + "inf,0,1e-6,0\n"), "rec.csv:2: column 'time': 'inf' is not a finite number");
  EXPECT_EQ(spiral_error_of(h + "0,0,1e-6, \n"), "rec.csv:2: column 'deflection': empty cell");
  EXPECT_EQ(spiral_error_of(h + "0,0,1e-6,0\n0.01,0.5,1e-6\n"),
            "rec.csv:3: ragged row: 3 cells, the header (line 1) names 4 columns");
  EXPECT_EQ(spiral_error_of(h + "0,0,1e-6,0,7\n"), "rec.csv:2: ragged row: 5 cells, the header (line 1) names 4 columns");
  EXPECT_EQ(spiral_error_of(h + "0,0,-1e-06,0\n"),
            "rec.csv:2: column 'radius': -1e-06 m is negative (the distance from the spindle axis is >= 0)");
  const std::string hi = "time,index,radius,deflection\n";
  EXPECT_EQ(spiral_error_of(hi + "0,0,1,0\n1,2,1,0\n"),
            "rec.csv:3: column 'index': 2 is not 0 or 1 (the index pulse is a logic level)");
  EXPECT_EQ(spiral_error_of(hi + "0,0.5,1,0\n"),
            "rec.csv:2: column 'index': 0.5 is not 0 or 1 (the index pulse is a logic level)");
}

TEST(RecordedSpiral, TimeErrorsNameLineAndColumn) {
  const std::string h = "time,angle,radius,deflection\n";
  EXPECT_EQ(spiral_error_of(h + "0,0,1,0\n0.002,0.5,1,0\n0.001,1,1,0\n"),
            "rec.csv:4: column 'time': 0.001 s is not after the previous sample's 0.002 s (line 3): time must "
            "increase strictly");
  EXPECT_EQ(spiral_error_of(h + "0,0,1,0\n0,0.5,1,0\n"),
            "rec.csv:3: column 'time': 0 s is not after the previous sample's 0 s (line 2): time must increase "
            "strictly");
  // Δt0 = 0.01; 0.0101 is off by 1 %, beyond 0.1 %; 0.010005 (0.05 %) is accepted.
  char interval[32];  // the shortest text that reads back to the double 0.0301 − 0.02
  *std::to_chars(interval, interval + 31, 0.0301 - 0.02).ptr = '\0';
  EXPECT_EQ(spiral_error_of(h + "0,0,1,0\n0.01,0.5,1,0\n0.02,1,1,0\n0.0301,1.5,1,0\n"),
            std::string("rec.csv:5: column 'time': non-uniform sampling: the interval ") + interval +
                " s from line 4 differs from the first interval 0.01 s (line 3) by more than 0.1 %");
  std::string jitter = h;
  for (int k = 0; k < 40; ++k) jitter += g17(0.01 * k + (k % 2 ? 5e-6 : 0.0)) + "," + g17(0.5 * k) + ",1,0\n";
  EXPECT_EQ(spiral_error_of(jitter), "");
}

TEST(RecordedSpiral, AngleErrorsNameLineAndColumn) {
  const std::string h = "time,angle,radius,deflection\n";
  EXPECT_EQ(spiral_error_of(h + "0,1,1,0\n0.01,1.5,1,0\n0.02,1.4,1,0\n"),
            "rec.csv:4: column 'angle': the spindle goes backwards or stands still: 1.4 rad after 1.5 rad on the "
            "previous sample, 1.4 rad after 1.5 rad unwrapped (a step below -pi counts as one wrap)");
  EXPECT_NE(spiral_error_of(h + "0,1,1,0\n0.01,1,1,0\n").find("rec.csv:3: column 'angle': the spindle goes backwards or "
                                                       "stands still"),
            std::string::npos);
  // A step of −7 is one wrap (+2π) and still −0.72: backwards.
  EXPECT_NE(spiral_error_of(h + "0,3,1,0\n0.01,-4,1,0\n").find("rec.csv:3: column 'angle': the spindle goes backwards"),
            std::string::npos);
  // Less than one revolution: at construction; 1.5 revolutions: when the end is reached (line of the last row).
  EXPECT_EQ(spiral_error_of(good_rows(10)),
            "rec.csv:11: column 'angle': the data end after 0.716 revolutions: a recorded spiral needs at least two "
            "revolutions");
  EXPECT_EQ(spiral_error_of(good_rows(20) + "# trailing comment\n"),
            "rec.csv:21: column 'angle': the data end after 1.512 revolutions: a recorded spiral needs at least two "
            "revolutions");
  EXPECT_EQ(spiral_error_of(good_rows(27)), "");  // 13 rad > 4π
}

TEST(RecordedSpiral, IndexModeNeedsThreeEdges) {
  auto file = [](const std::string& levels) {
    std::string text = "time,index,radius,deflection\n";
    for (std::size_t k = 0; k < levels.size(); ++k) text += std::to_string(k) + "," + levels[k] + ",1,0\n";
    return text;
  };
  EXPECT_EQ(spiral_error_of(file("0100")),
            "rec.csv:5: column 'index': the data end after 1 index edge: a recorded spiral needs at least two "
            "revolutions (three index edges)");
  // Two edges: the first revolution is delivered, then the end of the data fails.
  auto r = reader_of(file("01001000"));
  SpiralSample x{};
  for (int m = 0; m < 3; ++m) ASSERT_TRUE(r.next(x));
  EXPECT_THROW(r.next(x), InputError);
  EXPECT_EQ(spiral_error_of(file("01001000")),
            "rec.csv:9: column 'index': the data end after 2 index edges: a recorded spiral needs at least two "
            "revolutions (three index edges)");
  EXPECT_EQ(spiral_error_of(file("010010010")), "");
  EXPECT_EQ(spiral_error_of(file("111")).substr(0, 51), "rec.csv:4: column 'index': the data end after 0 ind");
}

TEST(RecordedSpiral, LateErrorComesFromNextWithItsLineAndStays) {
  std::string text = good_rows(400);
  text += "4,200,oops,0\n";  // line 402
  auto r = reader_of(text);
  SpiralSample x{};
  long delivered = 0;
  std::string message;
  try {
    while (r.next(x)) ++delivered;
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(delivered, 400);
  EXPECT_EQ(message, "rec.csv:402: column 'radius': 'oops' is not a finite number");
  try {
    r.next(x);
    ADD_FAILURE() << "no error on the second call";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

TEST(RecordedSpiral, OverlongLineIsRejected) {
  const std::string text = "time,angle,radius,deflection\n0,0,1," + std::string(1 << 20, '0') + "\n";
  EXPECT_EQ(spiral_error_of(text), "rec.csv:2: line longer than 1048576 bytes (not a recorded spiral CSV?)");
}

TEST(RecordedSpiral, FilesByPath) {
  scan_test::TempDir dir("afmkit_recorded_spiral");
  const std::string path = dir.file("spiral.csv");
  const Spiral s;
  scan_test::spit(path, csv(s, Encoding::index));
  RecordedSpiralReader r(path);
  EXPECT_TRUE(r.uses_index_pulse());
  EXPECT_GT(read_all(r).size(), 250u);  // 2 of 3.65 revolutions kept (137 samples each)

  scan_test::spit(dir.file("bad.csv"), good_rows(3) + "0.03,x,1,0\n");
  try {
    RecordedSpiralReader bad(dir.file("bad.csv"));
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir.file("bad.csv") + ":5: column 'angle': 'x' is not a finite number");
  }
  try {
    RecordedSpiralReader missing(dir.file("none.csv"));
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "cannot open recorded spiral '" + dir.file("none.csv") + "': No such file or directory");
  }
  try {
    RecordedSpiralReader folder(dir.path.string());
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "recorded spiral '" + dir.path.string() + "' is a directory, not a regular file");
  }
}

// issue 24 §3: a recorded deflection near 1e300 was read as any finite number, and the filter's sums overflowed
// (nan in every output row); deflections are bounded like the sample heights, [-1, 1] m, naming line and column.
TEST(RecordedSpiral, ADeflectionBeyondOneMetreIsRefusedNamingLineAndColumn) {
  const std::string h = "time,angle,radius,deflection\n";
  EXPECT_EQ(spiral_error_of(h + "0,0,1e-6,0\n0.01,0.5,1e-6,8.39e197\n"),
            "rec.csv:3: column 'deflection': 8.39e+197 m is out of range: a recorded deflection must lie in [-1, 1] m");
  EXPECT_EQ(spiral_error_of(h + "0,0,1e-6,-1.5\n"),
            "rec.csv:2: column 'deflection': -1.5 m is out of range: a recorded deflection must lie in [-1, 1] m");
  EXPECT_EQ(spiral_error_of(h + "0,0,1e-6,-1\n"), "rec.csv:2: column 'angle': the data end after 0.000 revolutions: a recorded "
                                           "spiral needs at least two revolutions")
      << "a deflection of exactly 1 m is accepted (the error is the next rule's)";
}
