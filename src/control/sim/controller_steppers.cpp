#include "controller_steppers.hpp"

#include <bit>

#include "afmkit/control/discretisation.hpp"

namespace afmkit::control::detail {

// ---- BankAb3 -------------------------------------------------------------------------------------------------

BankAb3::BankAb3(const OscillatorBank& bank, double step)
    : harmonics_(bank.harmonics()), h_(step), gain_(bank.gain()), a0_(bank.a0()) {
  const int n = harmonics_;
  freq_.resize(n);
  a_.resize(n);
  b_.resize(n);
  kept_.resize(n);
  for (int k = 1; k <= n; ++k) {
    freq_(k - 1) = k * bank.rotation_frequency();
    a_(k - 1) = bank.a(k);
    b_(k - 1) = bank.b(k);
    kept_(k - 1) = bank.is_rejected(k) ? 0.0 : 1.0;
    if (bank.is_rejected(k)) rejected_index_.push_back(2 * k - 1);
  }
  z_ = Eigen::VectorXd::Zero(bank.state_size());
  for (auto& d : d_) d = Eigen::VectorXd::Zero(bank.state_size());
}

double BankAb3::output() const {
  double s = 0.0;
  for (int i : rejected_index_) s += z_(i);
  return -gain_ * s;
}

void BankAb3::derivative(double m, Eigen::VectorXd& d) const {
  // e = m − x0 − Σ_kept x_k; ẋ0 = a0 e; ẋ_k = −kΩ z_k + a_k e; ż_k = kΩ x_k + b_k e   (eq. 15)
  const double* z = z_.data();
  double e = m - z[0];
  for (int k = 0; k < harmonics_; ++k) e -= kept_(k) * z[2 * k + 1];
  double* out = d.data();
  out[0] = a0_ * e;
  for (int k = 0; k < harmonics_; ++k) {
    const double x = z[2 * k + 1], y = z[2 * k + 2], w = freq_(k);
    out[2 * k + 1] = -w * y + a_(k) * e;
    out[2 * k + 2] = w * x + b_(k) * e;
  }
}

void BankAb3::step(double m, OutputPolynomial* poly) {
  derivative(m, d_[cur_]);
  const Eigen::VectorXd& d0 = d_[cur_];
  const Eigen::VectorXd& d1 = d_[(cur_ + 2) % 3];
  const Eigen::VectorXd& d2 = d_[(cur_ + 1) % 3];
  if (poly) {
    double c1 = 0, c2 = 0, c3 = 0;
    for (int i : rejected_index_) {
      const auto c = ab_dense(count_, h_, d0(i), d1(i), d2(i));
      c1 += c[0];
      c2 += c[1];
      c3 += c[2];
    }
    *poly = {output(), -gain_ * c1, -gain_ * c2, -gain_ * c3};
  }
  const AbCoefficients ab = ab_coefficients(count_);
  const double h0 = h_ * ab.beta0, h1 = h_ * ab.beta1, h2 = h_ * ab.beta2;
  const Eigen::Index n = z_.size();
  double* z = z_.data();
  const double *p0 = d0.data(), *p1 = d1.data(), *p2 = d2.data();
  for (Eigen::Index i = 0; i < n; ++i) z[i] += h0 * p0[i] + h1 * p1[i] + h2 * p2[i];
  cur_ = (cur_ + 1) % 3;
  ++count_;
}

// ---- BankZoh -------------------------------------------------------------------------------------------------

BankZoh::BankZoh(const OscillatorBank& bank, double step) {
  using cplx = std::complex<double>;
  const double omega = bank.rotation_frequency(), gain = bank.gain();
  const std::vector<cplx> lambda = bank_eigenvalues(bank);
  // D(s) = 1 + a0/s + Σ_kept G_k, D', N(s) = Σ_rejected G_k at s (eq. 18), O(N)
  const auto terms = [&](cplx s, cplx& d, cplx& dd, cplx& n) {
    d = 1.0 + bank.a0() / s;
    dd = -bank.a0() / (s * s);
    n = 0.0;
    for (int k = 1; k <= bank.harmonics(); ++k) {
      const double kw = k * omega;
      const cplx den = s * s + kw * kw;
      const cplx g = (bank.a(k) * s - bank.b(k) * kw) / den;
      if (bank.is_rejected(k)) {
        n += g;
      } else {
        d += g;
        dd += (bank.a(k) - 2.0 * s * g) / den;
      }
    }
  };
  for (const cplx l : lambda) {
    cplx beta, out;
    int rejected = 0;
    for (int k : bank.rejected())
      if (std::abs(std::abs(l.imag()) - k * omega) == 0.0 && l.real() == 0.0) rejected = k;
    cplx d, dd, n;
    if (rejected) {
      const cplx l_safe = l;
      d = 1.0 + bank.a0() / l_safe;
      for (int k = 1; k <= bank.harmonics(); ++k)
        if (!bank.is_rejected(k)) {
          const double kw = k * omega;
          d += (bank.a(k) * l - bank.b(k) * kw) / (l * l + kw * kw);
        }
      const double sign = l.imag() > 0.0 ? 1.0 : -1.0;
      beta = cplx(bank.a(rejected), sign * bank.b(rejected)) / (2.0 * d);
      out = -gain;
    } else {
      terms(l, d, dd, n);
      beta = 1.0 / dd;
      out = -gain * n;
    }
    const cplx z = l * step;
    const cplx e = std::exp(z);
    decay_.push_back(e);
    input_.push_back(beta * step * phi_function(1, z));  // β (e^{λh} − 1)/λ
    out_.push_back(out);
  }
  q_.assign(decay_.size(), 0.0);
}

double BankZoh::output() const {
  std::complex<double> u = 0.0;
  for (std::size_t j = 0; j < q_.size(); ++j) u += out_[j] * q_[j];
  return u.real();
}

void BankZoh::step(double m, OutputPolynomial* poly) {
  if (poly) *poly = {output(), 0.0, 0.0, 0.0};
  for (std::size_t j = 0; j < q_.size(); ++j) q_[j] = decay_[j] * q_[j] + input_[j] * m;
}

// ---- BankBlockZoh --------------------------------------------------------------------------------------------

BankBlockZoh::BankBlockZoh(const OscillatorBank& bank, double step) : g0_(bank.a0() * step) {
  for (int k = 1; k <= bank.harmonics(); ++k) {
    Eigen::Matrix2d j;
    j << 0.0, -k * bank.rotation_frequency(), k * bank.rotation_frequency(), 0.0;
    const ZeroOrderHold zoh = zero_order_hold(j, Eigen::Vector2d(bank.a(k), bank.b(k)), step);
    rot_.push_back(zoh.transition);
    in_.push_back(zoh.input.col(0));
  }
  z_ = Eigen::VectorXd::Zero(bank.state_size());
  c_ = -bank.output_vector();
  ce_ = bank.error_vector();
}

void BankBlockZoh::step(double m, OutputPolynomial* poly) {
  if (poly) *poly = {output(), 0.0, 0.0, 0.0};
  const double e = m - ce_.dot(z_);
  z_(0) += g0_ * e;
  for (std::size_t k = 0; k < rot_.size(); ++k) {
    auto seg = z_.segment<2>(static_cast<Eigen::Index>(2 * k + 1));
    const Eigen::Vector2d v = rot_[k] * seg + in_[k] * e;
    seg = v;
  }
}

// ---- NeutralAb3 ----------------------------------------------------------------------------------------------

NeutralAb3::NeutralAb3(const InfiniteBank& bank, int steps_per_period, double step)
    : a_(bank.a_coefficients()), b_(bank.b_coefficients()), n_(bank.n_coefficients()),
      period_steps_(steps_per_period), h_(step) {
  const std::size_t cap = std::bit_ceil(static_cast<std::size_t>(steps_per_period) + 8);
  wbuf_.assign(cap, 0.0);
  mbuf_.assign(cap, 0.0);
  mask_ = cap - 1;
}

void NeutralAb3::step(double m, OutputPolynomial* poly) {
  const long n = count_, M = period_steps_;
  const double m_T = delayed(mbuf_, n - M), w_T = delayed(wbuf_, n - M);  // Heaviside: 0 for t < T
  const double w = w_;
  std::array<double, 4>& d = d_[cur_];
  double r[4];
  for (int j = 0; j < 4; ++j) r[j] = n_[j] * (m - m_T) - (a_[j] * w - b_[j] * w_T);  // eq. 32
  d = {r[0], xi_[0] + r[1], xi_[1] + r[2], xi_[2] + r[3]};
  mbuf_[static_cast<std::size_t>(n) & mask_] = m;
  wbuf_[static_cast<std::size_t>(n) & mask_] = w;
  const auto& d1 = d_[(cur_ + 2) % 3];
  const auto& d2 = d_[(cur_ + 1) % 3];
  if (poly) {
    // u(t_n + s) = −(ξ4(s) + B4 w_T(s))/A4, w_T cubic through w at s = −h, 0, h, 2h (indices n−M−1 .. n−M+2).
    const auto c = ab_dense(count_, h_, d[3], d1[3], d2[3]);
    double v[4];
    for (int i = 0; i < 4; ++i) v[i] = n >= M ? delayed(wbuf_, n - M - 1 + i) : 0.0;
    const double q1 = -v[0] / 3.0 - v[1] / 2.0 + v[2] - v[3] / 6.0;
    const double q2 = (v[0] - 2.0 * v[1] + v[2]) / 2.0;
    const double q3 = (-v[0] + 3.0 * v[1] - 3.0 * v[2] + v[3]) / 6.0;
    const double s = -1.0 / a_[4], bb = b_[4];
    *poly = {-w, s * (c[0] + bb * q1 / h_), s * (c[1] + bb * q2 / (h_ * h_)), s * (c[2] + bb * q3 / (h_ * h_ * h_))};
  }
  const AbCoefficients ab = ab_coefficients(count_);
  for (int j = 0; j < 4; ++j) xi_[j] += h_ * (ab.beta0 * d[j] + ab.beta1 * d1[j] + ab.beta2 * d2[j]);
  cur_ = (cur_ + 1) % 3;
  ++count_;
  w_ = (xi_[3] + b_[4] * delayed(wbuf_, count_ - M)) / a_[4];  // eq. 33
}

}  // namespace afmkit::control::detail
