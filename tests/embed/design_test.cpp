// Host side of embedding: the magic-circle change of coordinates, the exporter's checks (a)–(d) and input
// validation, and a generated header compiled by the host C compiler and run on its own test vectors.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"
#include "afmkit/embed/c_header.hpp"
#include "afmkit/embed/design.hpp"
#include "embed_support.hpp"

namespace {
using namespace afmkit::embed;
using afmkit::InvalidParameter;

// S R(φ) S⁻¹ = [[1, −ε], [ε, 1 − ε²]] with S = [[1, 0], [ε/2, cos(φ/2)]], ε = 2 sin(φ/2): an identity checked here
// numerically for both signs of φ and up to |φ| near π (the design relies on it).
TEST(EmbedDesign, MagicCircleSimilarity) {
  for (double phi : {1e-4, -1e-4, 0.3, -0.3, 1.5, -2.5, 3.0, -3.1}) {
    Eigen::Matrix2d r, s, m;
    const double eps = 2.0 * std::sin(0.5 * phi);
    r << std::cos(phi), -std::sin(phi), std::sin(phi), std::cos(phi);
    s << 1.0, 0.0, 0.5 * eps, std::cos(0.5 * phi);
    m << 1.0, -eps, eps, 1.0 - eps * eps;
    EXPECT_LE((s * r * s.inverse() - m).cwiseAbs().maxCoeff(), 1e-13) << "phi = " << phi;
    EXPECT_NEAR(m.determinant(), 1.0, 1e-15);
  }
}

// The exported undamped pair has |ε| = 2 sin(kΩh/2) for its rejected harmonic k (rounded to the precision).
TEST(EmbedDesign, UndampedPairsAreTheRejectedHarmonics) {
  ExportSpec s = embed_test::reference_spec(Precision::Float, 6);
  s.rejected = {1, 3};
  const ExportedDesign d(s);
  ASSERT_EQ(d.circles(), 2);
  for (int j = 0; j < 2; ++j) {
    const int k = d.circle_harmonics()[static_cast<std::size_t>(j)];
    const double want = 2.0 * std::sin(0.5 * k * s.rotation_frequency / s.sample_rate);
    EXPECT_EQ(std::abs(d.circle_coefficients()[static_cast<std::size_t>(7 * j)]), static_cast<double>(static_cast<float>(want)));
  }
  EXPECT_EQ(d.state_size(), 13u);
}

std::string refusal(const ExportSpec& s) {
  try {
    const ExportedDesign d(s);
  } catch (const InvalidParameter& e) {
    std::printf("refused (%s): %s\n", e.parameter().c_str(), e.what());
    return e.parameter();
  }
  return "";
}

TEST(EmbedDesign, RefusesAnUnstableLoop) {  // (a)
  ExportSpec s = embed_test::reference_spec(Precision::Float);
  s.delay = 0.5 * 2.0 * std::numbers::pi / s.rotation_frequency;  // half a turn of delay with K = γ = 20 Ω
  EXPECT_EQ(refusal(s), "delay");
  s = embed_test::reference_spec(Precision::Float);
  s.alpha = -0.1 * s.rotation_frequency;  // unstable couplings even without delay
  EXPECT_EQ(refusal(s), "alpha");
  s = embed_test::reference_spec(Precision::Float);
  s.delay = 0.01 * 2.0 * std::numbers::pi / s.rotation_frequency;  // small delay: fine
  EXPECT_LT(ExportedDesign(s).spectral_abscissa(), 0.0);
}

TEST(EmbedDesign, RefusesWhatDoesNotFitTheTargetMemory) {  // (b)
  ExportSpec s = embed_test::reference_spec(Precision::Float, 10);
  const std::size_t need = ExportedDesign(s).footprint().total();
  s.target_memory = need;
  EXPECT_EQ(ExportedDesign(s).footprint().total(), need);  // exactly fits
  s.target_memory = need - 1;
  EXPECT_EQ(refusal(s), "harmonics");
  s.precision = Precision::Double;  // twice the bytes per number
  s.target_memory = need;
  EXPECT_EQ(refusal(s), "harmonics");
  try {
    s.precision = Precision::Float;
    s.target_memory = need - 1;
    ExportedDesign d(s);
  } catch (const InvalidParameter& e) {
    EXPECT_NE(std::string(e.what()).find("harmonics in [1, 9]"), std::string::npos) << e.what();
  }
}

TEST(EmbedDesign, RefusesASampleRateBelowNyquist) {  // (c)
  ExportSpec s = embed_test::reference_spec(Precision::Float, 10);
  s.sample_rate = 0.99 * s.harmonics * s.rotation_frequency / std::numbers::pi;
  EXPECT_EQ(refusal(s), "sample_rate");
  s.sample_rate = 1.01 * s.harmonics * s.rotation_frequency / std::numbers::pi;
  EXPECT_EQ(refusal(s), "");
}

TEST(EmbedDesign, RefusesUnresolvedFloatDampingButNotInDouble) {  // (d)
  ExportSpec s = embed_test::reference_spec(Precision::Float, 4);
  s.sample_rate = 1e8;  // damped modes decay by ~1e-7 per sample: below 64 float ulps of 1
  EXPECT_EQ(refusal(s), "sample_rate");
  s.precision = Precision::Double;
  const ExportedDesign d(s);
  EXPECT_LT(d.smallest_decay(), kFloatDecayUlps * std::ldexp(1.0, -24));
  EXPECT_GT(d.smallest_decay(), 0.0);
  s.precision = Precision::Float;
  s.sample_rate = 5000.0;
  EXPECT_GE(ExportedDesign(s).smallest_decay(), kFloatDecayUlps * std::ldexp(1.0, -24));
}

TEST(EmbedDesign, ValidatesItsInputs) {
  const ExportSpec good = embed_test::reference_spec(Precision::Float, 3);
  auto bad = [&](auto change) {
    ExportSpec s = good;
    change(s);
    return refusal(s);
  };
  EXPECT_EQ(bad([](ExportSpec& s) { s.sample_rate = std::nan(""); }), "sample_rate");
  EXPECT_EQ(bad([](ExportSpec& s) { s.rotation_frequency = -1.0; }), "rotation_frequency");
  EXPECT_EQ(bad([](ExportSpec& s) { s.harmonics = 0; }), "harmonics");
  EXPECT_EQ(bad([](ExportSpec& s) { s.harmonics = kMaxHarmonics + 1; }), "harmonics");
  EXPECT_EQ(bad([](ExportSpec& s) { s.gain = 0.0; }), "gain");
  EXPECT_EQ(bad([](ExportSpec& s) { s.plant_rate = INFINITY; }), "plant_rate");
  EXPECT_EQ(bad([](ExportSpec& s) { s.delay = -1.0; }), "delay");
  EXPECT_EQ(bad([](ExportSpec& s) { s.rejected = {4}; }), "rejected");
  EXPECT_EQ(bad([](ExportSpec& s) { s.rejected = {1, 1}; }), "rejected");
  EXPECT_EQ(bad([](ExportSpec& s) { s.input_limit = 1e31; }), "input_limit");
  EXPECT_EQ(bad([](ExportSpec& s) { s.alpha = NAN; }), "alpha");
  EXPECT_THROW(precision_from("half"), InvalidParameter);
  EXPECT_EQ(precision_from("double"), Precision::Double);
  const ExportedDesign d(good);
  EXPECT_THROW(make_test_vectors(d, 0), InvalidParameter);
  EXPECT_THROW(make_test_vectors(d, 1000001), InvalidParameter);
}

// The generated header, compiled with the host C compiler (C99, all warnings as errors) together with the core
// source, run on its own test vectors: the program prints PASS. Also: the precision guard stops a mismatched build.
std::string run(const std::string& cmd) {
  std::FILE* p = popen(cmd.c_str(), "r");
  if (!p) return "popen failed";
  std::string out;
  char buf[256];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int rc = pclose(p);
  return out + (rc == 0 ? "" : "[exit " + std::to_string(rc) + "]");
}

TEST(EmbedDesign, GeneratedHeaderCompilesAndPassesOnTheHost) {
  if (std::system("cc --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "no host C compiler `cc`";
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("afmkit_embed_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string src = AFMKIT_SOURCE_DIR;
  std::ofstream(dir / "main.c") << R"(#include <math.h>
#include <stdio.h>
#include "export.h"
int main(void) {
  afmkit_embed_real state[AFMKIT_EXPORT_STATE_SIZE];
  afmkit_embed_filter f;
  afmkit_embed_real u = 0;
  long n;
  if (afmkit_embed_init(&f, &afmkit_export_coefficients, state, AFMKIT_EXPORT_STATE_SIZE) != AFMKIT_EMBED_OK) {
    puts("INIT FAILED");
    return 1;
  }
  for (n = 0; n < AFMKIT_EXPORT_TEST_SAMPLES; ++n) {
    const double m = afmkit_export_test_input[n] + u / AFMKIT_EXPORT_GAIN;
    if (!(fabs(m - afmkit_export_test_expected[n]) <= AFMKIT_EXPORT_TEST_TOLERANCE)) {
      printf("FAIL at %ld\n", n);
      return 1;
    }
    u = afmkit_embed_step(&f, (afmkit_embed_real)m);
  }
  puts("PASS");
  return 0;
}
)";
  for (Precision p : {Precision::Float, Precision::Double}) {
    ExportSpec s = embed_test::reference_spec(p, 10);
    s.delay = 0.02 * 2.0 * std::numbers::pi / s.rotation_frequency;
    const std::string header = export_c_header(s, 3000);
    EXPECT_NE(header.find("#define AFMKIT_EXPORT_TEST_SAMPLES 3000"), std::string::npos);
    EXPECT_NE(header.find("#define AFMKIT_EXPORT_STATE_SIZE 21"), std::string::npos);
    std::ofstream(dir / "export.h") << header;
    const std::string def = p == Precision::Double ? " -DAFMKIT_EMBED_DOUBLE" : "";
    const std::string cc = "cc -std=c99 -Wall -Wextra -Wpedantic -Werror -I" + src + "/include -I" + dir.string() +
                           " " + dir.string() + "/main.c " + src + "/src/embed/c/afmkit_embed.c -lm -o " +
                           dir.string() + "/prog";
    const std::string build = run(cc + def + " 2>&1");
    EXPECT_EQ(build, "") << to_string(p);
    EXPECT_EQ(run(dir.string() + "/prog"), "PASS\n") << to_string(p);
    // the other precision's build stops at the #error guard
    const std::string other = p == Precision::Double ? "" : " -DAFMKIT_EMBED_DOUBLE";
    const std::string wrong = run(cc + other + " 2>&1");
    EXPECT_NE(wrong.find("#error"), std::string::npos) << wrong;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
