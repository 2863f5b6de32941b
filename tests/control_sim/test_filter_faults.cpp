// Hostile use of the real-time filter (issue 12, item 3): huge samples, large N, destroyed and foreign handles.
// The modal set-up (O(N²), no N×N matrix) is checked against a dense reference computed here independently
// (Van Loan's augmented exponential by scaling and squaring of a Taylor series).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "afmkit/afmkit_c.h"
#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/core/error.hpp"

#include "../fig5_parameters.hpp"

using namespace afmkit::control;

namespace {
using afmkit_test::fig5::kOmega;
using afmkit_test::fig5::kT;
using afmkit_test::fig5::kGamma;

std::vector<double> signal(int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    v[static_cast<std::size_t>(i)] = 0.2 + std::sin(0.0314 * i) + 0.1 * std::sin(0.094 * i + 1.0);
  return v;
}

/// exp(M) by scaling and squaring of a 30-term Taylor series (dense reference for small matrices).
Eigen::MatrixXd expm_reference(const Eigen::MatrixXd& m) {
  const double norm = m.cwiseAbs().rowwise().sum().maxCoeff();
  const int squarings = norm > 0.5 ? static_cast<int>(std::ceil(std::log2(norm / 0.5))) : 0;
  const Eigen::MatrixXd a = m / std::ldexp(1.0, squarings);
  Eigen::MatrixXd term = Eigen::MatrixXd::Identity(m.rows(), m.cols()), sum = term;
  for (int k = 1; k <= 30; ++k) {
    term = term * a / k;
    sum += term;
  }
  for (int i = 0; i < squarings; ++i) sum = sum * sum;
  return sum;
}

struct DenseZoh {
  Eigen::MatrixXd phi;
  Eigen::VectorXd gamma;
  Eigen::RowVectorXd c;
};
/// The old dense computation: Φ, Γ from exp([[A, b], [0, 0]] h), u = −K c_rᵀ z.
DenseZoh dense_zoh(const OscillatorBank& bank, double fs) {
  const int n = bank.state_size();
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(n + 1, n + 1);
  aug.topLeftCorner(n, n) = bank.state_matrix();
  aug.topRightCorner(n, 1) = bank.input_vector();
  const Eigen::MatrixXd e = expm_reference(aug / fs);
  return {e.topLeftCorner(n, n), e.topRightCorner(n, 1), -bank.output_vector()};
}
}  // namespace

// ---- 1. input range ----------------------------------------------------------------------------------------------

TEST(FilterFaults, HugeSampleIsSkippedLikeNaNAndOutputStaysFinite) {
  const double fs = 400.0 / kT;
  auto f = RealtimeFilter::with_couplings(fs, kOmega, 10, 0.1, -0.1, kGamma);
  auto ref = RealtimeFilter::with_couplings(fs, kOmega, 10, 0.1, -0.1, kGamma);
  EXPECT_EQ(f.input_limit(), RealtimeFilter::kDefaultInputLimit);
  const auto sig = signal(100500);
  for (std::size_t i = 0; i < sig.size(); ++i) {
    double m = sig[i];
    if (i == 400) m = 1e308;
    if (i == 401) m = -1e200;
    if (i == 402) m = std::numeric_limits<double>::max();
    const double u = f.step(m);
    const double r = ref.step(i >= 400 && i <= 402 ? std::nan("") : m);  // the NaN path, reused exactly
    ASSERT_EQ(u, r) << i;
    ASSERT_TRUE(std::isfinite(u)) << i;
  }
  EXPECT_EQ(f.skipped_samples(), 3u);
  EXPECT_TRUE(f.controller_state().allFinite());
}

TEST(FilterFaults, InputLimitIsConfigurableAndValidated) {
  auto f = RealtimeFilter::with_couplings(400.0 / kT, kOmega, 4, 0.1, -0.1, kGamma);
  f.set_input_limit(10.0);
  f.step(1.0);
  const double held = f.step(2.0);
  EXPECT_EQ(f.step(10.5), held);
  EXPECT_EQ(f.step(-11.0), held);
  EXPECT_NE(f.step(10.0), held);  // the limit itself is accepted
  EXPECT_EQ(f.skipped_samples(), 2u);
  f.reset();
  EXPECT_EQ(f.input_limit(), 10.0);  // configuration, kept by reset
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity(), 1e151}) {
    try {
      f.set_input_limit(bad);
      ADD_FAILURE() << bad;
    } catch (const afmkit::InvalidParameter& e) {
      EXPECT_EQ(std::string(e.parameter()), "input_limit");
      EXPECT_NE(std::string(e.what()).find("(0, 1e+150]"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(f.input_limit(), 10.0);
}

// ---- 2. set-up cost and range of N -------------------------------------------------------------------------------

TEST(FilterFaults, ModalSetupEqualsDenseReferenceForSmallN) {
  for (int n = 1; n <= 20; ++n) {
    for (const auto& rejected : {std::vector<int>{1}, std::vector<int>{1, 3}}) {
      if (rejected.back() > n) continue;
      const auto bank = OscillatorBank::with_couplings(kOmega, n, 0.1, -0.1, kGamma, rejected);
      const double fs = 40.0 * n / kT;
      RealtimeFilter f(bank, fs);
      ASSERT_TRUE(f.uses_modal_form()) << n;
      const DenseZoh ref = dense_zoh(bank, fs);
      EXPECT_LT((f.transition_matrix() - ref.phi).norm(), 1e-12 * ref.phi.norm()) << n;
      EXPECT_LT((f.input_vector() - ref.gamma).norm(), 1e-12 * ref.gamma.norm()) << n;
      EXPECT_LT((f.output_vector() - ref.c).norm(), 1e-12 * ref.c.norm()) << n;
      // outputs over 3000 samples from the dense recursion
      Eigen::VectorXd z = Eigen::VectorXd::Zero(bank.state_size());
      double worst = 0.0, scale = 0.0;
      for (double m : signal(3000)) {
        const double u_ref = ref.c.dot(z);
        worst = std::max(worst, std::abs(f.step(m) - u_ref));
        scale = std::max(scale, std::abs(u_ref));
        z = ref.phi * z + ref.gamma * m;
      }
      EXPECT_LT(worst, 1e-12 * scale) << n;
      EXPECT_LT((f.controller_state() - z).norm(), 1e-12 * z.norm()) << n;
    }
  }
}

TEST(FilterFaults, CreationAtN1000ThroughTheCApi) {
  char err[512];
  afmkit_filter* h = afmkit_filter_create(40.0 * 1000 / kT, kOmega, 1000, 0.1, -0.1, kGamma, err, sizeof err);
  ASSERT_NE(h, nullptr) << err;
  for (double m : signal(2000)) ASSERT_TRUE(std::isfinite(afmkit_filter_step(h, m)));
  EXPECT_EQ(afmkit_filter_destroy_checked(h), AFMKIT_OK);
  auto f = RealtimeFilter::with_couplings(40.0 * 1000 / kT, kOmega, 1000, 0.1, -0.1, kGamma);
  EXPECT_TRUE(f.uses_modal_form());
  // state round trip through the physical coordinates (O(N²), no N×N matrix)
  for (double m : signal(500)) f.step(m);
  const Eigen::VectorXd z = f.controller_state();
  f.set_controller_state(z);
  EXPECT_LT((f.controller_state() - z).norm(), 1e-10 * z.norm());
}

TEST(FilterFaults, UpperEndOfTheDocumentedRangeOfN) {
  char err[512];
  const int n = RealtimeFilter::kMaxHarmonics;  // zero-order hold
  afmkit_filter* h = afmkit_filter_create(4.0 * n / kT, kOmega, n, 0.1, -0.1, kGamma, err, sizeof err);
  ASSERT_NE(h, nullptr) << err;
  for (double m : signal(200)) ASSERT_TRUE(std::isfinite(afmkit_filter_step(h, m)));
  afmkit_filter_destroy(h);
  EXPECT_EQ(afmkit_filter_create(4.0 * (n + 1) / kT, kOmega, n + 1, 0.1, -0.1, kGamma, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("harmonics = 10001 is out of range: must be an integer in [1, 10000]"),
            std::string::npos)
      << err;

  const int nb = RealtimeFilter::kMaxHarmonicsBlock;  // block form
  std::vector<double> a(static_cast<std::size_t>(nb), 0.2), b(static_cast<std::size_t>(nb), -0.1);
  h = afmkit_filter_create_general(4.0 * nb / kT, kOmega, nb, 0.1, a.data(), b.data(), kGamma, nullptr, 0,
                                   AFMKIT_FORM_BLOCK_ZERO_ORDER_HOLD, err, sizeof err);
  ASSERT_NE(h, nullptr) << err;
  for (double m : signal(20)) ASSERT_TRUE(std::isfinite(afmkit_filter_step(h, m)));
  afmkit_filter_destroy(h);
  a.push_back(0.2);
  b.push_back(-0.1);
  EXPECT_EQ(afmkit_filter_create_general(4.0 * (nb + 1) / kT, kOmega, nb + 1, 0.1, a.data(), b.data(), kGamma, nullptr,
                                         0, AFMKIT_FORM_BLOCK_ZERO_ORDER_HOLD, err, sizeof err),
            nullptr);
  EXPECT_NE(std::string(err).find("[1, 100000]"), std::string::npos) << err;
}

TEST(FilterFaults, IllConditionedCouplingsAtLargeNAreRejectedWithTheRange) {
  // a0 = 0 (alpha = 0): no modal form; the dense fallback is limited to N <= kMaxDenseHarmonics
  char err[512];
  afmkit_filter* h = afmkit_filter_create(40.0 * 5 / kT, kOmega, 5, 0.0, -0.1, kGamma, err, sizeof err);
  ASSERT_NE(h, nullptr) << err;
  afmkit_filter_destroy(h);
  const int n = RealtimeFilter::kMaxDenseHarmonics + 1;
  EXPECT_EQ(afmkit_filter_create(40.0 * n / kT, kOmega, n, 0.0, -0.1, kGamma, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("harmonics"), std::string::npos) << err;
  EXPECT_NE(std::string(err).find("[1, 200]"), std::string::npos) << err;
}

// ---- 3. handles --------------------------------------------------------------------------------------------------

TEST(FilterFaults, UseAfterDestroyAndDoubleDestroyAreErrors) {
  afmkit_filter* h = afmkit_filter_create(400.0 / kT, kOmega, 4, 0.1, -0.1, kGamma, nullptr, 0);
  ASSERT_NE(h, nullptr);
  EXPECT_EQ(afmkit_filter_check(h), AFMKIT_OK);
  EXPECT_EQ(afmkit_filter_destroy_checked(h), AFMKIT_OK);
  // everything on the stale handle: an error, no dereference (must also hold under AddressSanitizer)
  EXPECT_EQ(afmkit_filter_check(h), AFMKIT_INVALID_HANDLE);
  EXPECT_TRUE(std::isnan(afmkit_filter_step(h, 1.0)));
  double in[2] = {1.0, 2.0}, out[2];
  std::vector<double> buf(100);
  EXPECT_EQ(afmkit_filter_step_block(h, in, out, 2), AFMKIT_INVALID_HANDLE);
  EXPECT_EQ(afmkit_filter_reset(h), AFMKIT_INVALID_HANDLE);
  EXPECT_EQ(afmkit_filter_set_parameters(h, 400.0 / kT, kOmega, 4, 0.1, -0.1, kGamma), AFMKIT_INVALID_HANDLE);
  EXPECT_EQ(afmkit_filter_set_input_limit(h, 1.0), AFMKIT_INVALID_HANDLE);
  EXPECT_TRUE(std::isnan(afmkit_filter_input_limit(h)));
  EXPECT_EQ(afmkit_filter_state_size(h), 0u);
  EXPECT_EQ(afmkit_filter_save_state(h, buf.data(), buf.size()), AFMKIT_INVALID_HANDLE);
  EXPECT_EQ(afmkit_filter_restore_state(h, buf.data(), buf.size()), AFMKIT_INVALID_HANDLE);
  EXPECT_EQ(afmkit_filter_skipped_samples(h), 0u);
  EXPECT_NE(std::string(afmkit_filter_last_error(h)).find("invalid handle"), std::string::npos);
  EXPECT_EQ(afmkit_filter_destroy_checked(h), AFMKIT_INVALID_HANDLE);  // double destroy
  afmkit_filter_destroy(h);                                             // ignored, no crash
  EXPECT_EQ(afmkit_filter_destroy_checked(nullptr), AFMKIT_OK);
  EXPECT_EQ(afmkit_filter_check(nullptr), AFMKIT_NULL_HANDLE);
}

TEST(FilterFaults, StaleHandleStaysInvalidWhenItsSlotIsReused) {
  afmkit_filter* stale = afmkit_filter_create(400.0 / kT, kOmega, 2, 0.1, -0.1, kGamma, nullptr, 0);
  ASSERT_NE(stale, nullptr);
  afmkit_filter_destroy(stale);
  // more create/destroy cycles than there are slots: every slot, the stale one included, is reused
  for (int i = 0; i < 5000; ++i) {
    afmkit_filter* g = afmkit_filter_create(400.0 / kT, kOmega, 1, 0.1, -0.1, kGamma, nullptr, 0);
    ASSERT_NE(g, nullptr);
    ASSERT_NE(g, stale);
    EXPECT_EQ(afmkit_filter_check(stale), AFMKIT_INVALID_HANDLE);
    afmkit_filter_destroy(g);
  }
  afmkit_filter* live = afmkit_filter_create(400.0 / kT, kOmega, 2, 0.1, -0.1, kGamma, nullptr, 0);
  EXPECT_EQ(afmkit_filter_destroy_checked(stale), AFMKIT_INVALID_HANDLE);
  EXPECT_EQ(afmkit_filter_check(live), AFMKIT_OK);  // the stale destroy did not touch the live filter
  afmkit_filter_destroy(live);
}

TEST(FilterFaults, ForeignHandlesAreRejected) {
  double not_a_filter[64] = {};
  for (auto* h : {reinterpret_cast<afmkit_filter*>(not_a_filter),
                  // handle-like (odd) values: a generation never reached, and one that is never live (even)
                  reinterpret_cast<afmkit_filter*>(~std::uintptr_t{0} ^ 6u),
                  reinterpret_cast<afmkit_filter*>((std::uintptr_t{2} << 13) | 11u),
                  reinterpret_cast<afmkit_filter*>(~std::uintptr_t{0})}) {
    EXPECT_EQ(afmkit_filter_check(h), AFMKIT_INVALID_HANDLE);
    EXPECT_TRUE(std::isnan(afmkit_filter_step(h, 1.0)));
    EXPECT_EQ(afmkit_filter_destroy_checked(h), AFMKIT_INVALID_HANDLE);
  }
}
