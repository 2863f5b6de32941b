// The C API (include/afmkit/afmkit_c.h) used through its C functions only, compared with the C++ RealtimeFilter.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "afmkit/afmkit_c.h"
#include "afmkit/control/realtime_filter.hpp"

#include "../fig5_parameters.hpp"

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kGamma;
const double kCapiRate = 2000.0 / (2.0 * std::numbers::pi);

std::vector<double> test_signal(int n) {
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) v[i] = 0.2 + std::sin(0.00314 * i) + 0.1 * std::sin(0.0094 * i + 1.0);
  return v;
}
}  // namespace

TEST(CApi, CreateStepDestroyMatchesCppFilter) {
  char err[256] = "x";
  afmkit_filter* h = afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma, err, sizeof err);
  ASSERT_NE(h, nullptr);
  EXPECT_STREQ(err, "");
  auto ref = afmkit::control::RealtimeFilter::with_couplings(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma);
  for (double m : test_signal(3000)) ASSERT_EQ(afmkit_filter_step(h, m), ref.step(m));
  afmkit_filter_destroy(h);
  afmkit_filter_destroy(nullptr);  // allowed
  EXPECT_STRNE(afmkit_c_version(), "");
}

TEST(CApi, InvalidInputReturnsNullAndMessage) {
  char err[256];
  EXPECT_EQ(afmkit_filter_create(3.0, kOmega, 10, 0.1, -0.1, kGamma, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("sample_rate"), std::string::npos) << err;
  EXPECT_NE(std::string(err).find("Nyquist"), std::string::npos) << err;
  EXPECT_EQ(afmkit_filter_create(kCapiRate, -1.0, 10, 0.1, -0.1, kGamma, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("rotation_frequency"), std::string::npos) << err;
  EXPECT_EQ(afmkit_filter_create(kCapiRate, kOmega, 0, 0.1, -0.1, kGamma, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("harmonics"), std::string::npos) << err;
  EXPECT_EQ(afmkit_filter_create(kCapiRate, kOmega, 10, std::nan(""), -0.1, kGamma, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("alpha"), std::string::npos) << err;
  EXPECT_EQ(afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, 0.0, nullptr, 0), nullptr);  // no buffer: still safe
  char tiny[8];
  EXPECT_EQ(afmkit_filter_create(3.0, kOmega, 10, 0.1, -0.1, kGamma, tiny, sizeof tiny), nullptr);
  EXPECT_EQ(std::strlen(tiny), 7u);  // truncated, NUL-terminated
}

TEST(CApi, GeneralBankAndForms) {
  const double a[3] = {0.2, 0.2, 0.2}, b[3] = {0.2, 0.1, 0.0667};
  const int rej[2] = {1, 3};
  char err[256];
  afmkit_filter* h = afmkit_filter_create_general(kCapiRate, kOmega, 3, 0.1, a, b, kGamma, rej, 2,
                                                  AFMKIT_FORM_BLOCK_ZERO_ORDER_HOLD, err, sizeof err);
  ASSERT_NE(h, nullptr) << err;
  afmkit::control::RealtimeFilter ref(
      afmkit::control::OscillatorBank(kOmega, 0.1, {0.2, 0.2, 0.2}, {0.2, 0.1, 0.0667}, kGamma, {1, 3}), kCapiRate,
      afmkit::control::SampledForm::BlockZeroOrderHold);
  for (double m : test_signal(500)) ASSERT_EQ(afmkit_filter_step(h, m), ref.step(m));
  afmkit_filter_destroy(h);
  EXPECT_EQ(afmkit_filter_create_general(kCapiRate, kOmega, 3, 0.1, a, b, kGamma, rej, 2, 7, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("form"), std::string::npos);
  EXPECT_EQ(afmkit_filter_create_general(kCapiRate, kOmega, 3, 0.1, nullptr, b, kGamma, nullptr, 0, 0, err, sizeof err),
            nullptr);
  const int bad_rej[1] = {4};
  EXPECT_EQ(afmkit_filter_create_general(kCapiRate, kOmega, 3, 0.1, a, b, kGamma, bad_rej, 1, 0, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("rejected"), std::string::npos) << err;
}

TEST(CApi, BlockResetSkipAndCounters) {
  afmkit_filter* h = afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma, nullptr, 0);
  ASSERT_NE(h, nullptr);
  std::vector<double> in = test_signal(1000), out(1000);
  in[500] = std::numeric_limits<double>::quiet_NaN();
  in[501] = std::numeric_limits<double>::infinity();
  ASSERT_EQ(afmkit_filter_step_block(h, in.data(), out.data(), in.size()), AFMKIT_OK);
  EXPECT_EQ(out[500], out[499]);
  EXPECT_EQ(out[501], out[499]);
  EXPECT_EQ(afmkit_filter_skipped_samples(h), 2u);
  EXPECT_TRUE(std::isfinite(out[999]));
  ASSERT_EQ(afmkit_filter_reset(h), AFMKIT_OK);
  EXPECT_EQ(afmkit_filter_skipped_samples(h), 0u);
  EXPECT_EQ(afmkit_filter_step(h, 1.0), 0.0);  // zero state: u_0 = 0
  EXPECT_EQ(afmkit_filter_step_block(h, nullptr, out.data(), 3), AFMKIT_NULL_HANDLE);
  EXPECT_EQ(afmkit_filter_step_block(h, nullptr, nullptr, 0), AFMKIT_OK);
  afmkit_filter_destroy(h);
  // NULL handle everywhere: no crash
  EXPECT_TRUE(std::isnan(afmkit_filter_step(nullptr, 1.0)));
  EXPECT_EQ(afmkit_filter_step_block(nullptr, in.data(), out.data(), 1), AFMKIT_NULL_HANDLE);
  EXPECT_EQ(afmkit_filter_reset(nullptr), AFMKIT_NULL_HANDLE);
  EXPECT_EQ(afmkit_filter_set_parameters(nullptr, kCapiRate, kOmega, 10, 0.1, -0.1, kGamma), AFMKIT_NULL_HANDLE);
  EXPECT_EQ(afmkit_filter_state_size(nullptr), 0u);
  EXPECT_EQ(afmkit_filter_save_state(nullptr, out.data(), out.size()), AFMKIT_NULL_HANDLE);
  EXPECT_EQ(afmkit_filter_restore_state(nullptr, out.data(), out.size()), AFMKIT_NULL_HANDLE);
  EXPECT_EQ(afmkit_filter_skipped_samples(nullptr), 0u);
  EXPECT_STREQ(afmkit_filter_last_error(nullptr), "null handle");
}

TEST(CApi, BumplessSetParameters) {
  afmkit_filter* h = afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma, nullptr, 0);
  afmkit_filter* r = afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma, nullptr, 0);
  const auto sig = test_signal(5000);
  for (int i = 0; i < 4999; ++i) {
    afmkit_filter_step(h, sig[i]);
    afmkit_filter_step(r, sig[i]);
  }
  ASSERT_EQ(afmkit_filter_set_parameters(h, 1.2 * kCapiRate, kOmega, 8, 0.12, -0.08, 2.0 * kGamma), AFMKIT_OK);
  const double u_ref = afmkit_filter_step(r, sig[4999]), u_new = afmkit_filter_step(h, sig[4999]);
  EXPECT_GT(std::abs(u_ref), 1e-3);
  EXPECT_NEAR(u_new, u_ref, 1e-9 * std::abs(u_ref));
  // invalid change: status, message, filter unchanged
  std::vector<double> before(afmkit_filter_state_size(h)), after(before.size());
  ASSERT_EQ(afmkit_filter_save_state(h, before.data(), before.size()), AFMKIT_OK);
  EXPECT_EQ(afmkit_filter_set_parameters(h, 1.0, kOmega, 8, 0.12, -0.08, 2.0 * kGamma), AFMKIT_INVALID_ARGUMENT);
  EXPECT_NE(std::string(afmkit_filter_last_error(h)).find("sample_rate"), std::string::npos);
  ASSERT_EQ(afmkit_filter_save_state(h, after.data(), after.size()), AFMKIT_OK);
  EXPECT_EQ(before, after);
  afmkit_filter_destroy(h);
  afmkit_filter_destroy(r);
}

TEST(CApi, SaveRestoreBitForBit) {
  afmkit_filter* h = afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma, nullptr, 0);
  const auto sig = test_signal(2000);
  for (int i = 0; i < 1000; ++i) afmkit_filter_step(h, sig[i]);
  const size_t n = afmkit_filter_state_size(h);
  ASSERT_GT(n, 21u);
  std::vector<double> buf(n);
  EXPECT_EQ(afmkit_filter_save_state(h, buf.data(), n - 1), AFMKIT_BUFFER_TOO_SMALL);
  EXPECT_NE(std::string(afmkit_filter_last_error(h)).find("state_size"), std::string::npos);
  ASSERT_EQ(afmkit_filter_save_state(h, buf.data(), n), AFMKIT_OK);
  std::vector<double> first;
  for (int i = 1000; i < 2000; ++i) first.push_back(afmkit_filter_step(h, sig[i]));
  afmkit_filter* g = afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma, nullptr, 0);
  ASSERT_EQ(afmkit_filter_restore_state(g, buf.data(), n), AFMKIT_OK);
  for (int i = 1000; i < 2000; ++i) ASSERT_EQ(afmkit_filter_step(g, sig[i]), first[i - 1000]);
  buf[0] = 0.0;
  EXPECT_EQ(afmkit_filter_restore_state(g, buf.data(), n), AFMKIT_INVALID_ARGUMENT);
  EXPECT_NE(std::string(afmkit_filter_last_error(g)).find("state"), std::string::npos);
  EXPECT_EQ(afmkit_filter_restore_state(g, nullptr, n), AFMKIT_NULL_HANDLE);
  afmkit_filter_destroy(h);
  afmkit_filter_destroy(g);
}

// A buffer no filter saved is refused whole, the filter unchanged: the overflow-prone values (coordinates near
// DBL_MAX, counters beyond 2^64 whose conversion to uint64 is undefined) as well as the structural ones.
TEST(CApi, RestoreRefusesStatesNoFilterCouldHaveSaved) {
  afmkit_filter* h = afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma, nullptr, 0);
  ASSERT_NE(h, nullptr);
  const auto sig = test_signal(2000);
  for (int i = 0; i < 1000; ++i) afmkit_filter_step(h, sig[i]);
  const size_t n = afmkit_filter_state_size(h);
  std::vector<double> good(n);
  ASSERT_EQ(afmkit_filter_save_state(h, good.data(), n), AFMKIT_OK);
  struct Case {
    size_t index;
    double value;
    const char* names;
  };
  const Case cases[] = {
      {10, 1e308, "entry [10]"},            // an internal coordinate near DBL_MAX
      {n - 1, -1e300, "coordinates"},      // a physical coordinate (used when the configuration differs)
      {6, 1e300, "held output"},           // the held output
      {8, 1e300, "counter [8]"},           // samples processed beyond 2^64: the conversion would be undefined
      {7, 18446744073709551616.0, "counter [7]"},  // exactly 2^64
      {8, 1000.5, "counter [8]"},          // fractional
      {7, 1e6, "skipped samples"},         // more skipped than processed (1000)
      {2, 1e300, "N must be"},             // N: sizes are checked before any conversion
      {3, -1e300, "inconsistent sizes"},
      {4, 1e300, "fingerprint"},
  };
  for (const Case& c : cases) {
    std::vector<double> bad = good;
    bad[c.index] = c.value;
    EXPECT_EQ(afmkit_filter_restore_state(h, bad.data(), n), AFMKIT_INVALID_ARGUMENT) << c.index;
    EXPECT_NE(std::string(afmkit_filter_last_error(h)).find(c.names), std::string::npos)
        << c.index << ": " << afmkit_filter_last_error(h);
    std::vector<double> now(n);
    ASSERT_EQ(afmkit_filter_save_state(h, now.data(), n), AFMKIT_OK);
    EXPECT_EQ(now, good) << c.index;  // unchanged
  }
  // the largest values a filter could have saved are still taken
  std::vector<double> edge = good;
  edge[7] = 1000.0;
  edge[8] = 18446744073709549568.0;  // 2^64 - 2048, the largest double below 2^64
  EXPECT_EQ(afmkit_filter_restore_state(h, edge.data(), n), AFMKIT_OK) << afmkit_filter_last_error(h);
  afmkit_filter_destroy(h);
}

TEST(CApi, InputLimitSkipsHugeSamples) {
  afmkit_filter* h = afmkit_filter_create(kCapiRate, kOmega, 10, 0.1, -0.1, kGamma, nullptr, 0);
  ASSERT_NE(h, nullptr);
  EXPECT_EQ(afmkit_filter_input_limit(h), AFMKIT_DEFAULT_INPUT_LIMIT);
  std::vector<double> in = test_signal(20000), out(in.size());
  in[100] = 1e308;  // finite but huge: skipped like NaN, the output stays finite
  ASSERT_EQ(afmkit_filter_step_block(h, in.data(), out.data(), in.size()), AFMKIT_OK);
  EXPECT_EQ(out[100], out[99]);
  EXPECT_EQ(afmkit_filter_skipped_samples(h), 1u);
  for (double u : out) ASSERT_TRUE(std::isfinite(u));
  ASSERT_EQ(afmkit_filter_set_input_limit(h, 1.0), AFMKIT_OK);
  EXPECT_EQ(afmkit_filter_input_limit(h), 1.0);
  const double held = afmkit_filter_step(h, 0.5);
  EXPECT_EQ(afmkit_filter_step(h, 1.5), held);
  EXPECT_EQ(afmkit_filter_skipped_samples(h), 2u);
  EXPECT_EQ(afmkit_filter_set_input_limit(h, 0.0), AFMKIT_INVALID_ARGUMENT);
  const std::string msg = afmkit_filter_last_error(h);
  EXPECT_NE(msg.find("input_limit"), std::string::npos) << msg;
  EXPECT_NE(msg.find("(0, 1e+150]"), std::string::npos) << msg;
  EXPECT_EQ(afmkit_filter_input_limit(h), 1.0);  // unchanged on error
  afmkit_filter_destroy(h);
}
