// JPK .jpk-force archives: the real file's known values (shared data README, from afmformats' tests) and hostile
// archives (truncated, wrong magic, lying sizes).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "afmkit/core/error.hpp"
#include "afmkit/io/curves/read_curves.hpp"
#include "real_files.hpp"

namespace ac = afmkit::io::curves;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string jpk_error_of(const std::string& bytes, ac::ReadOptions o = {}) {
  try {
    ac::parse_curves(bytes, "x.jpk-force", ".jpk-force", o);
  } catch (const afmkit::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(CurvesJpk, KnownValuesOfTheRealFile) {
  CURVES_REAL_FILE(path, "jpk_spot3-0192.jpk-force");
  const auto curves = ac::read_curves(path);
  ASSERT_EQ(curves.size(), 1u);
  const auto& c = curves[0];
  EXPECT_EQ(c.metadata.format, "jpk-force");
  EXPECT_NEAR(c.metadata.spring_constant, 0.04349, 5e-6);  // README: 0.04349 N/m
  ASSERT_EQ(c.segments.size(), 2u);                       // extend, retract (the pause has no points)
  const auto& a = c.segments[0];
  EXPECT_EQ(a.kind, ac::SegmentKind::approach);
  EXPECT_EQ(c.segments[1].kind, ac::SegmentKind::retract);
  ASSERT_EQ(a.size(), 2000u);
  // README: first approach sample force -5.145579192349918e-10 N (JPK's vDeflection force, positive repulsive as
  // ours: unchanged), measured (strain gauge) height 2.2815672438768612e-05 m (JPK's height grows away from the
  // sample as ours: unchanged); the default height is the measured one.
  EXPECT_NEAR(a.force[0], -5.145579192349918e-10, 1e-22);
  EXPECT_NEAR(a.height[0], 2.2815672438768612e-05, 1e-17);
  EXPECT_NEAR(a.deflection[0] * c.metadata.spring_constant, a.force[0], 1e-22);
  EXPECT_LT(a.height.back(), a.height.front());  // extend: towards the sample
  EXPECT_GT(a.force.back(), a.force.front());    // repulsive at the end of the extend
  ASSERT_EQ(a.time.size(), 2000u);
  EXPECT_DOUBLE_EQ(a.time[0], 0.0);
  EXPECT_NEAR(c.segments[1].time[0], 1.0, 1e-12);  // after the 1 s extend
}

TEST(CurvesJpk, PiezoHeightByName) {
  CURVES_REAL_FILE(path, "jpk_spot3-0192.jpk-force");
  ac::ReadOptions o;
  o.height.name = "height";
  const auto c = ac::read_curves(path, o)[0];
  EXPECT_NEAR(c.segments[0].height[0], 2.8783223430683289e-05, 1e-17);  // README: height (piezo)
}

TEST(CurvesJpk, TruncatedArchivesAreRefusedNamingTheFile) {
  CURVES_REAL_FILE(path, "jpk_spot3-0192.jpk-force");
  const std::string bytes = slurp(path);
  for (std::size_t cut : {std::size_t{0}, std::size_t{3}, std::size_t{100}, bytes.size() / 2, bytes.size() - 10}) {
    const std::string msg = jpk_error_of(bytes.substr(0, cut));
    EXPECT_NE(msg.find("x.jpk-force"), std::string::npos) << cut << ": " << msg;
  }
}

TEST(CurvesJpk, CorruptedEntryIsRefusedNamingTheEntry) {
  CURVES_REAL_FILE(path, "jpk_spot3-0192.jpk-force");
  std::string bytes = slurp(path);
  // Flip bytes inside the first entry's data (after its local header): its CRC no longer matches.
  for (std::size_t i = 200; i < 260; ++i) bytes[i] = static_cast<char>(bytes[i] ^ 0x5a);
  const std::string msg = jpk_error_of(bytes);
  EXPECT_NE(msg.find("x.jpk-force"), std::string::npos) << msg;
  EXPECT_NE(msg.find("entry"), std::string::npos) << msg;
}

TEST(CurvesJpk, WrongMagicAsJpkIsRefused) {
  ac::ReadOptions o;
  o.format = "jpk-force";
  const std::string msg = jpk_error_of("Height (nm)\tDefl (nm)\n1\t2\n", o);
  EXPECT_NE(msg.find("not a readable JPK"), std::string::npos) << msg;
}

TEST(CurvesJpk, AnEntryDeclaringMoreThanItCanHoldIsRefusedBeforeAllocation) {
  std::ifstream in(std::string(AFMKIT_SOURCE_DIR) + "/fuzz/corpus/fuzz_io_curves_jpk/shared_layout_deflated",
                   std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  std::string bytes = s.str();
  ASSERT_FALSE(bytes.empty());
  // Every entry's uncompressed size (local header offset 22, central directory offset 24) := 2^31 - 1 bytes.
  const std::uint32_t huge = 0x7fffffff;
  int patched = 0;
  for (std::size_t at = 0; at + 30 < bytes.size(); ++at) {
    if (bytes.compare(at, 4, std::string("PK\x03\x04", 4)) == 0) std::memcpy(&bytes[at + 22], &huge, 4), ++patched;
    if (bytes.compare(at, 4, std::string("PK\x01\x02", 4)) == 0) std::memcpy(&bytes[at + 24], &huge, 4), ++patched;
  }
  ASSERT_GE(patched, 4);
  const std::string msg = jpk_error_of(bytes);
  EXPECT_NE(msg.find("x.jpk-force"), std::string::npos) << msg;
  EXPECT_NE(msg.find("declares 2147483647 bytes"), std::string::npos) << msg;
}
