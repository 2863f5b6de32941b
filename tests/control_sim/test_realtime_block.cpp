// RealtimeFilter::step_block: the same bits as step() sample by sample, in both vector widths, through skipped
// samples and state save/restore; and the modal recursion as documented (ModalCoefficients) reproduces step().
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/core/error.hpp"

namespace {
using afmkit::control::ModalCoefficients;
using afmkit::control::RealtimeFilter;
using afmkit::control::SampledForm;
using V = RealtimeFilter::Vectorisation;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Offset + tilt + harmonics 2..4 + noise, with NaN, ±inf and out-of-limit samples sprinkled in.
std::vector<double> hostile_signal(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::uniform_int_distribution<int> pick(0, 199);
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double th = kTwoPi * static_cast<double>(i) / 997.0;
    v[i] = 0.3 + std::sin(th + 0.2) + 0.2 * std::cos(2 * th) + 0.05 * std::sin(3 * th - 1.0) + noise(rng);
    switch (pick(rng)) {
      case 0: v[i] = std::numeric_limits<double>::quiet_NaN(); break;
      case 1: v[i] = std::numeric_limits<double>::infinity(); break;
      case 2: v[i] = -std::numeric_limits<double>::infinity(); break;
      case 3: v[i] = 1e200; break;  // beyond the default input limit
      default: break;
    }
  }
  return v;
}

RealtimeFilter make(int harmonics) {
  const double fs = std::max(997.0, 40.0 * harmonics) / kTwoPi;  // Ω = 1 rad/s
  return RealtimeFilter::with_couplings(fs, 1.0, harmonics, 0.1, -0.1, 20.0);
}

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

class BlockEqualsStep : public ::testing::TestWithParam<int> {};

TEST_P(BlockEqualsStep, BitForBitInBothWidthsAndAnyBlockSizes) {
  const int n_harm = GetParam();
  const auto in = hostile_signal(20000, 7u + static_cast<unsigned>(n_harm));
  RealtimeFilter ref = make(n_harm);
  ASSERT_TRUE(ref.uses_modal_form());
  std::vector<double> expected(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) expected[i] = ref.step(in[i]);
  ASSERT_GT(ref.skipped_samples(), 100u);  // the skip path is exercised

  for (V width : {V::Auto, V::Portable, V::Avx2, V::Avx512}) {  // a build the processor lacks: a narrower one
    RealtimeFilter f = make(n_harm);
    f.set_vectorisation(width);
    std::vector<double> out(in.size(), -1.0);
    std::mt19937 rng(3);
    std::uniform_int_distribution<std::size_t> block(1, 700);
    std::size_t pos = 0;
    while (pos < in.size()) {  // blocks of random sizes, some of one sample
      const std::size_t len = std::min(block(rng), in.size() - pos);
      f.step_block(std::span(in).subspan(pos, len), std::span(out).subspan(pos, len));
      pos += len;
    }
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < in.size(); ++i) mismatches += !same_bits(out[i], expected[i]);
    EXPECT_EQ(mismatches, 0u) << "N = " << n_harm << " build " << static_cast<int>(f.vectorisation());
    EXPECT_EQ(f.skipped_samples(), ref.skipped_samples());
    EXPECT_EQ(f.samples(), ref.samples());
    EXPECT_TRUE(same_bits(f.last_output(), ref.last_output()));
    EXPECT_EQ(f.save_state(), ref.save_state());
  }
}

TEST_P(BlockEqualsStep, InPlaceAndAfterRestoreState) {
  const int n_harm = GetParam();
  const auto in = hostile_signal(6000, 11u);
  RealtimeFilter a = make(n_harm), b = make(n_harm);
  std::vector<double> ua(in.size());
  for (std::size_t i = 0; i < 3000; ++i) ua[i] = a.step(in[i]);
  std::vector<double> buf(in.begin(), in.end());
  b.step_block(std::span(buf).first(3000), std::span(buf).first(3000));  // in place
  const auto saved = b.save_state();
  RealtimeFilter c = make(n_harm);
  c.restore_state(saved);
  for (std::size_t i = 3000; i < in.size(); ++i) ua[i] = a.step(in[i]);
  c.step_block(std::span(buf).subspan(3000), std::span(buf).subspan(3000));
  for (std::size_t i = 0; i < in.size(); ++i) ASSERT_TRUE(same_bits(buf[i], ua[i])) << "sample " << i;
}

INSTANTIATE_TEST_SUITE_P(Harmonics, BlockEqualsStep, ::testing::Values(1, 2, 7, 10, 11, 12, 50, 120));

// Each build forced in turn (a build this processor lacks is skipped, with a message): the same bits as step(),
// sample for sample, on long random inputs, for N from one group of four modes to beyond the register-resident
// sizes of every build (AVX-512: up to 8 groups, N ≤ 31; AVX2: 4 groups; 16-byte: 3 groups).
class ForcedBuildSameBits : public ::testing::TestWithParam<V> {};

TEST_P(ForcedBuildSameBits, AsStepSampleForSample) {
  const V build = GetParam();
  if (!RealtimeFilter::vectorisation_available(build))
    GTEST_SKIP() << "this processor lacks the " << (build == V::Avx512 ? "AVX-512 (F, VL, DQ, BW)" : "AVX2")
                 << " build of the modal kernel (or the compiler did not make it): not compared";
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> uni(-2.0, 2.0);
  std::uniform_int_distribution<std::size_t> block(1, 3000);
  for (int n_harm : {1, 4, 10, 13, 17, 21, 25, 29, 35}) {
    auto in = hostile_signal(30000, 101u + static_cast<unsigned>(n_harm));
    for (double& x : in)
      if (std::isfinite(x) && std::abs(x) < 10.0) x += uni(rng);  // broadband on top: every mode excited
    RealtimeFilter ref = make(n_harm), f = make(n_harm);
    f.set_vectorisation(build);
    ASSERT_EQ(f.vectorisation(), build);
    std::vector<double> expected(in.size()), out(in.size(), -1.0);
    for (std::size_t i = 0; i < in.size(); ++i) expected[i] = ref.step(in[i]);
    for (std::size_t pos = 0; pos < in.size();) {
      const std::size_t len = std::min(block(rng), in.size() - pos);
      f.step_block(std::span(in).subspan(pos, len), std::span(out).subspan(pos, len));
      pos += len;
    }
    std::size_t mismatches = 0, first = in.size();
    for (std::size_t i = 0; i < in.size(); ++i)
      if (!same_bits(out[i], expected[i])) first = std::min(first, i), ++mismatches;
    EXPECT_EQ(mismatches, 0u) << "N = " << n_harm << ", first at sample " << first;
    EXPECT_EQ(f.skipped_samples(), ref.skipped_samples());
    EXPECT_EQ(f.save_state(), ref.save_state()) << "N = " << n_harm;
  }
}

INSTANTIATE_TEST_SUITE_P(Builds, ForcedBuildSameBits, ::testing::Values(V::Portable, V::Avx2, V::Avx512),
                         [](const ::testing::TestParamInfo<V>& i) {
                           return std::string(i.param == V::Portable ? "Portable"
                                              : i.param == V::Avx2   ? "Avx2"
                                                                     : "Avx512");
                         });

TEST(ForcedBuildSameBits, AutoIsTheWidestAvailableAndALackingBuildFallsBack) {
  RealtimeFilter f = make(10);
  const V widest = RealtimeFilter::vectorisation_available(V::Avx512) ? V::Avx512
                   : RealtimeFilter::vectorisation_available(V::Avx2) ? V::Avx2
                                                                      : V::Portable;
  EXPECT_EQ(f.vectorisation(), widest);  // the constructor chooses Auto
  f.set_vectorisation(V::Portable);
  EXPECT_EQ(f.vectorisation(), V::Portable);
  EXPECT_FALSE(f.uses_wide_vectors());
  f.set_vectorisation(V::Avx512);
  EXPECT_EQ(f.vectorisation(), widest);  // Avx512 if available, else the widest below it
  f.set_vectorisation(V::Avx2);
  EXPECT_EQ(f.vectorisation(), RealtimeFilter::vectorisation_available(V::Avx2) ? V::Avx2 : V::Portable);
  f.set_vectorisation(V::Auto);
  EXPECT_EQ(f.vectorisation(), widest);
  EXPECT_TRUE(RealtimeFilter::vectorisation_available(V::Portable));
}

TEST(ModalCoefficients, TheDocumentedRecursionReproducesStep) {
  // An independent scalar implementation of the recursion stated for ModalCoefficients (pairs, then reals; output
  // from the old state), summed in another order: equal to step() to rounding.
  for (int n_harm : {1, 10, 50}) {
    RealtimeFilter f = make(n_harm);
    const ModalCoefficients mc = f.modal_coefficients();
    ASSERT_EQ(2 * mc.pairs.size() + mc.reals.size(), static_cast<std::size_t>(2 * n_harm + 1));
    int rejected = 0;
    for (const auto& p : mc.pairs) {
      EXPECT_EQ(p.c1, p.c2);
      EXPECT_EQ(p.s1, -p.s2);
      EXPECT_GT(p.eigenvalue.imag(), 0.0);
      if (p.rejected_harmonic) {  // λ = ikΩ exactly: |e^{λh}| = 1 up to the rounding of cos, sin
        ++rejected;
        EXPECT_EQ(p.eigenvalue.real(), 0.0);
        EXPECT_NEAR(std::hypot(p.c1, p.s2), 1.0, 1e-15);
      } else {
        EXPECT_LT(std::hypot(p.c1, p.s2), 1.0);
      }
    }
    EXPECT_EQ(rejected, 1);  // harmonic 1 only
    std::vector<double> q1(mc.pairs.size(), 0.0), q2(mc.pairs.size(), 0.0), qr(mc.reals.size(), 0.0);
    const auto in = hostile_signal(5000, 5u);
    double worst = 0.0, scale = 0.0;
    for (double m : in) {
      if (!std::isfinite(m) || std::abs(m) > f.input_limit()) continue;  // only accepted samples here
      double u = 0.0;
      for (std::size_t j = mc.reals.size(); j-- > 0;) u += mc.reals[j].w * qr[j];
      for (std::size_t j = mc.pairs.size(); j-- > 0;) u += mc.pairs[j].w1 * q1[j] + mc.pairs[j].w2 * q2[j];
      for (std::size_t j = 0; j < mc.pairs.size(); ++j) {
        const auto& p = mc.pairs[j];
        const double a = q1[j], b = q2[j];
        q1[j] = p.c1 * a + p.s1 * b + p.g1 * m;
        q2[j] = p.c2 * b + p.s2 * a + p.g2 * m;
      }
      for (std::size_t j = 0; j < mc.reals.size(); ++j) qr[j] = mc.reals[j].r * qr[j] + mc.reals[j].g * m;
      const double v = f.step(m);
      worst = std::max(worst, std::abs(v - u));
      scale = std::max(scale, std::abs(v));
    }
    EXPECT_GT(scale, 0.1);
    EXPECT_LT(worst, 1e-12 * scale) << "N = " << n_harm;
    // the state is the same too
    const auto q = f.modal_state();
    for (std::size_t j = 0; j < mc.pairs.size(); ++j) {
      EXPECT_NEAR(q[2 * j], q1[j], 1e-11 * scale);
      EXPECT_NEAR(q[2 * j + 1], q2[j], 1e-11 * scale);
    }
  }
}

TEST(ModalCoefficients, OnlyForTheModalForm) {
  auto block = RealtimeFilter::with_couplings(100.0, 1.0, 3, 0.1, -0.1, 1.0, SampledForm::BlockZeroOrderHold);
  try {
    (void)block.modal_coefficients();
    FAIL() << "expected InvalidParameter";
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_EQ(e.parameter(), "form");
  }
  EXPECT_THROW((void)block.modal_state(), afmkit::InvalidParameter);
}

TEST(BlockEqualsStep, OtherFormsToo) {
  // the block zero-order-hold form and the dense fallback loop step() (no vectorised block path): still equal
  const auto in = hostile_signal(3000, 9u);
  auto a = RealtimeFilter::with_couplings(200.0, 1.0, 5, 0.1, -0.1, 2.0, SampledForm::BlockZeroOrderHold);
  auto b = a;
  std::vector<double> out(in.size());
  b.step_block(in, out);
  for (std::size_t i = 0; i < in.size(); ++i) ASSERT_TRUE(same_bits(out[i], a.step(in[i])));
}

}  // namespace
