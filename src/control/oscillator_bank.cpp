#include "afmkit/control/oscillator_bank.hpp"

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

OscillatorBank::OscillatorBank(double omega, double a0, std::vector<double> a, std::vector<double> b, double gain,
                               std::vector<int> rejected)
    : omega_(validate::positive("rotation_frequency", omega)),
      a0_(validate::finite("a0", a0)),
      gain_(validate::positive("gain", gain)),
      a_(std::move(a)),
      b_(std::move(b)),
      rejected_(std::move(rejected)) {
  if (a_.empty()) throw InvalidParameter("harmonics", "harmonics = 0 is out of range: must be >= 1");
  if (a_.size() != b_.size())
    throw InvalidParameter("b", fmt::format("b has {} entries but a has {}: both need N entries", b_.size(), a_.size()));
  for (std::size_t k = 0; k < a_.size(); ++k) {
    validate::finite(fmt::format("a[{}]", k + 1), a_[k]);
    validate::finite(fmt::format("b[{}]", k + 1), b_[k]);
  }
  if (rejected_.empty()) throw InvalidParameter("rejected", "rejected harmonics: the list must not be empty");
  rejected_mask_.assign(a_.size() + 1, 0);
  for (int k : rejected_) {
    validate::in_range("rejected", static_cast<long>(k), 1L, static_cast<long>(a_.size()));
    if (rejected_mask_[k]) throw InvalidParameter("rejected", fmt::format("rejected: harmonic {} listed twice", k));
    rejected_mask_[k] = 1;
  }
}

OscillatorBank OscillatorBank::with_couplings(double omega, int n, double alpha, double beta, double gain,
                                              std::vector<int> rejected) {
  validate::in_range("harmonics", static_cast<long>(n), 1L, 100000L);
  validate::finite("alpha", alpha);
  validate::finite("beta", beta);
  std::vector<double> a(n, 2.0 * alpha), b(n);
  for (int k = 1; k <= n; ++k) b[k - 1] = -2.0 * beta / k;
  return OscillatorBank(omega, alpha, std::move(a), std::move(b), gain, std::move(rejected));
}

OscillatorBank OscillatorBank::single(double omega, double a, double b, double gain) {
  return OscillatorBank(omega, 0.0, {a}, {b}, gain, {1});
}

bool OscillatorBank::is_rejected(int k) const {
  return k >= 1 && k < static_cast<int>(rejected_mask_.size()) && rejected_mask_[k];
}

OscillatorBank OscillatorBank::with_gain(double gain) const {
  OscillatorBank c = *this;
  c.gain_ = validate::positive("gain", gain);
  return c;
}

Eigen::VectorXd OscillatorBank::input_vector() const {
  Eigen::VectorXd b(state_size());
  b(0) = a0_;
  for (int k = 1; k <= harmonics(); ++k) {
    b(2 * k - 1) = a_[k - 1];
    b(2 * k) = b_[k - 1];
  }
  return b;
}

Eigen::RowVectorXd OscillatorBank::error_vector() const {
  Eigen::RowVectorXd c = Eigen::RowVectorXd::Zero(state_size());
  c(0) = 1.0;
  for (int k = 1; k <= harmonics(); ++k)
    if (!is_rejected(k)) c(2 * k - 1) = 1.0;
  return c;
}

Eigen::RowVectorXd OscillatorBank::output_vector() const {
  Eigen::RowVectorXd c = Eigen::RowVectorXd::Zero(state_size());
  for (int k : rejected_) c(2 * k - 1) = gain_;
  return c;
}

Eigen::MatrixXd OscillatorBank::state_matrix() const {
  const int n = state_size();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k <= harmonics(); ++k) {
    a(2 * k - 1, 2 * k) = -k * omega_;
    a(2 * k, 2 * k - 1) = k * omega_;
  }
  a -= input_vector() * error_vector();
  return a;
}

}  // namespace afmkit::control
