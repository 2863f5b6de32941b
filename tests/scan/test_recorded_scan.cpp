// A recorded spiral filtered offline through the real-time filter: the first harmonic goes, harmonics 2 and 3 stay
// (checked by an independent DFT of the input and of the tilt-free output), the images cover the recorded disc,
// angle and index-pulse recordings agree, and the sample-by-sample output equals a RealtimeFilter driven by hand
// in the same loop (the object of the C API).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <fstream>
#include <numbers>
#include <vector>

#include <fmt/format.h>

#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/scan/recorded_scan.hpp"
#include "scan_test_dir.hpp"

namespace {
using namespace afmkit::scan;

// 50 Hz spindle, 4 kHz sampling (80 samples per turn), 60 turns from 1 mm outwards at 0.2 µm per turn:
// d = 1 µm·(r/1 mm) sin(θ + 0.3) (tilt) + 20 nm sin(2θ + 1) + 10 nm cos 3θ + 5 nm.
double signal(double theta, double r) {
  return 1e-6 * (r / 1e-3) * std::sin(theta + 0.3) + 20e-9 * std::sin(2 * theta + 1) + 10e-9 * std::cos(3 * theta) +
         5e-9;
}
constexpr int kPerTurn = 80, kTurns = 60;

void write_recording(const std::string& path, bool index_pulse) {
  std::ofstream f(path);
  f << (index_pulse ? "time,radius,index,deflection\n" : "time,radius,angle,deflection\n");
  for (int n = 0; n <= kPerTurn * kTurns; ++n) {
    const double t = n / 4000.0, theta = 2 * std::numbers::pi * 50 * t, r = 1e-3 + 0.2e-6 * 50 * t;
    if (index_pulse)
      f << fmt::format("{},{},{},{}\n", t, r, n % kPerTurn == 0 ? 1 : 0, signal(theta, r));
    else
      f << fmt::format("{},{},{},{}\n", t, r, std::fmod(theta, 2 * std::numbers::pi), signal(theta, r));
  }
}

struct Recorder final : ScanObserver {
  std::vector<ScanSample> samples;
  bool sample(const ScanSample& s) override {
    samples.push_back(s);
    return true;
  }
};

std::complex<double> harmonic_of_turn(const std::vector<ScanSample>& v, int turn, int k, bool tilt_free) {
  std::complex<double> sum = 0;
  for (int j = 0; j < kPerTurn; ++j) {
    const ScanSample& s = v[static_cast<std::size_t>(turn * kPerTurn + j)];
    sum += (tilt_free ? s.topography : s.deflection) * std::exp(std::complex<double>(0, -k * s.angle));
  }
  return 2.0 * sum / static_cast<double>(kPerTurn);
}

TEST(RecordedScan, RemovesTheFirstHarmonicKeepsTheOthers) {
  scan_test::TempDir dir("recorded_scan");
  const std::string path = dir.file("spiral.csv");
  write_recording(path, false);
  Recorder rec;
  std::vector<TurnRecord> turns;
  RecordedScanOptions o;
  o.extra = &rec;
  o.on_turn = [&](const TurnRecord& r) { turns.push_back(r); };
  const RecordedScan scan = filter_recorded_scan(path, RecordedFilterSpec{}, 64, o);
  EXPECT_NEAR(scan.survey.rotation_frequency, 2 * std::numbers::pi * 50, 1e-9);
  EXPECT_NEAR(scan.survey.sample_rate, 4000, 1e-9);
  EXPECT_EQ(scan.survey.samples, kPerTurn * kTurns + 1);
  ASSERT_EQ(rec.samples.size(), static_cast<std::size_t>(kPerTurn * kTurns + 1));
  const int late = kTurns - 2;
  const double tilt = std::abs(harmonic_of_turn(rec.samples, late, 1, false));
  EXPECT_NEAR(tilt, 1.0e-6 * 1.0 + 1e-6 * (late + 0.5) * 0.2e-3, 2e-9);  // the input, for the record
  // the tilt grows by 0.2 nm per turn: the residual is the controller's tracking error of that ramp, far below it
  EXPECT_LT(std::abs(harmonic_of_turn(rec.samples, late, 1, true)), 1e-3 * tilt);
  for (int k : {2, 3}) {
    const auto in = harmonic_of_turn(rec.samples, late, k, false), out = harmonic_of_turn(rec.samples, late, k, true);
    EXPECT_LT(std::abs(out - in), 1e-3 * std::abs(in)) << "harmonic " << k;
  }
  // the offset (harmonic 0) is kept: 5 nm (the input's mean over a turn is off by the growing tilt's leakage)
  double mean_out = 0;
  for (int j = 0; j < kPerTurn; ++j) mean_out += rec.samples[late * kPerTurn + j].topography / kPerTurn;
  EXPECT_NEAR(mean_out, 5e-9, 1e-3 * 5e-9);
  ASSERT_GE(turns.size(), 59u);
  EXPECT_LT(turns[late].deflection_first_harmonic, 1e-3 * turns[late].surface_first_harmonic);
  // images: every pixel between the first and last turn is valid, none outside
  EXPECT_GT(scan.tilt_free.valid_count(), 0u);
  const Grid& g = scan.tilt_free.grid();
  long bad = 0;
  for (long j = 0; j < g.y_resolution; ++j)
    for (long i = 0; i < g.x_resolution; ++i) {
      const double r = std::hypot(g.x_offset + (i + 0.5) * scan.tilt_free.dx(),
                                  g.y_offset + (j + 0.5) * scan.tilt_free.dy());
      const bool inside = r > 1e-3 + 1e-6 && r < 1e-3 + 0.2e-6 * (kTurns - 1);
      const bool outside = r < 1e-3 - 1e-6 || r > 1e-3 + 0.2e-6 * kTurns + 1e-6;
      if (inside && !scan.tilt_free.valid(i, j)) ++bad;
      if (outside && scan.tilt_free.valid(i, j)) ++bad;
    }
  EXPECT_EQ(bad, 0);
}

TEST(RecordedScan, IsTheRealtimeFilterInTheVirtualLoop) {
  scan_test::TempDir dir("recorded_scan_loop");
  const std::string path = dir.file("spiral.csv");
  write_recording(path, false);
  Recorder rec;
  RecordedScanOptions o;
  o.extra = &rec;
  filter_recorded_scan(path, RecordedFilterSpec{7, 0.2, -0.05}, 64, o);
  auto f = afmkit::control::RealtimeFilter::with_couplings(4000, 2 * std::numbers::pi * 50, 7, 0.2 * 2 * std::numbers::pi * 50,
                                                           -0.05 * 2 * std::numbers::pi * 50, 3.0);  // any K
  double previous = 0;
  double worst = 0;
  for (const ScanSample& s : rec.samples) {
    const double m = s.deflection + previous / 3.0;
    previous = f.step(m);
    worst = std::max(worst, std::abs(m - s.topography));
  }
  EXPECT_LT(worst, 1e-20);  // K-invariant up to rounding of u/K (1e-14 of the 1 µm signal)
}

TEST(RecordedScan, IndexPulseRecordingGivesTheSameSignal) {
  scan_test::TempDir dir("recorded_scan_index");
  write_recording(dir.file("angle.csv"), false);
  write_recording(dir.file("index.csv"), true);
  Recorder a, b;
  RecordedScanOptions oa, ob;
  oa.extra = &a;
  ob.extra = &b;
  filter_recorded_scan(dir.file("angle.csv"), RecordedFilterSpec{}, 64, oa);
  const RecordedScan with_index = filter_recorded_scan(dir.file("index.csv"), RecordedFilterSpec{}, 64, ob);
  EXPECT_TRUE(with_index.survey.uses_index_pulse);
  // the first row cannot be a rising edge: the recording starts at the second pulse, one turn in
  EXPECT_EQ(with_index.survey.dropped_samples, kPerTurn);
  ASSERT_EQ(b.samples.size() + kPerTurn, a.samples.size());
  // the pulses fall exactly on the samples of angle 0, so the angles agree to rounding; the filter starts a turn
  // later, so the tilt-free signals agree once both have converged
  for (std::size_t i = 0; i < b.samples.size(); i += 97) {
    const ScanSample& x = a.samples[i + kPerTurn];
    EXPECT_NEAR(std::remainder(b.samples[i].angle - x.angle, 2 * std::numbers::pi), 0.0, 1e-9);
    EXPECT_EQ(b.samples[i].deflection, x.deflection);
    if (i > 40 * kPerTurn) {
      EXPECT_NEAR(b.samples[i].topography, x.topography, 1e-3 * 1e-6);
    }
  }
}

TEST(RecordedScan, BadRatesAndGeometryAreNamed) {
  scan_test::TempDir dir("recorded_scan_bad");
  const std::string path = dir.file("spiral.csv");
  write_recording(path, false);
  try {
    filter_recorded_scan(path, RecordedFilterSpec{40, 0.1, -0.1}, 64);  // 40 × 50 Hz = 2 kHz = Nyquist
    FAIL();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "harmonics");
    EXPECT_NE(std::string(e.what()).find("[1, 39]"), std::string::npos) << e.what();
  }
  // the pitch (0.2 µm) exceeds a pixel only beyond 2·1.012 mm / 0.2 µm ≈ 10 000 pixels
  EXPECT_THROW(filter_recorded_scan(path, RecordedFilterSpec{}, 16000), afmkit::InvalidParameter);
}

}  // namespace

TEST(RecordedScan, EveryTurnsRadialSpreadIsSurveyedTheLastPartialOneToo) {
  // The regular spiral: every turn spreads one pitch (0.2 µm), the survey finds exactly that. One radius outlier
  // (1 mm further out) in the middle of a turn, in the first turn, or in the last, partial, turn: the survey's
  // largest spread is the outlier's distance from that turn's radii, and the image grid is refused.
  scan_test::TempDir dir("recorded_spread");
  auto write = [&](const std::string& name, int outlier, int samples) {
    std::ofstream f(dir.file(name));
    f << "time,radius,angle,deflection\n";
    for (int n = 0; n < samples; ++n) {
      const double t = n / 4000.0, theta = 2 * std::numbers::pi * 50 * t;
      const double r = n == outlier ? 2e-3 : 1e-3 + 0.2e-6 * 50 * t;
      f << fmt::format("{},{},{},{}\n", t, r, std::fmod(theta, 2 * std::numbers::pi), 0.0);
    }
    return dir.file(name);
  };
  const int samples = kPerTurn * 10 + kPerTurn / 2;  // 10.5 turns
  const RecordedSurvey regular = survey_recorded(write("regular.csv", -1, samples));
  EXPECT_NEAR(regular.max_pitch, 0.2e-6, 1e-12);
  EXPECT_EQ(regular.turns, 10);
  for (int outlier : {5, kPerTurn * 4 + 17, samples - 3}) {
    const std::string path = write("outlier.csv", outlier, samples);
    const RecordedSurvey s = survey_recorded(path);
    const double r_turn = 1e-3 + 0.2e-6 * 50 * (outlier / 4000.0);  // the turn's radius near the outlier
    EXPECT_NEAR(s.max_pitch, 2e-3 - r_turn, 0.3e-6) << outlier;
    EXPECT_NEAR(static_cast<double>(s.max_pitch_turn), outlier / kPerTurn, 1.0) << outlier;
    EXPECT_LE(s.max_pitch_time, outlier / 4000.0) << outlier;  // the turn holding the outlier starts before it
    EXPECT_GT(s.max_pitch_time, outlier / 4000.0 - 1.0 / 50.0 - 1e-9) << outlier;
    EXPECT_THROW(recorded_image_grid(s, 64), afmkit::InvalidParameter) << outlier;
  }
  EXPECT_NO_THROW(recorded_image_grid(regular, 64));
}
