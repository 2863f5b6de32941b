#include "afmkit/control/realtime_filter.hpp"

#include <cmath>
#include <cstring>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/control/discretisation.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::control {

namespace {
constexpr double kMagic = 1095781707.0;  // 0x41464D4B "AFMK"
constexpr double kLayoutVersion = 1.0;
constexpr std::size_t kHeader = 10;

void fnv(std::uint64_t& h, const void* p, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(p);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= b[i];
    h *= 1099511628211ULL;
  }
}

std::uint64_t fingerprint(const OscillatorBank& bank, double fs, int kind) {
  std::uint64_t h = 14695981039346656037ULL;
  auto mix = [&](double v) { fnv(h, &v, sizeof v); };
  mix(fs);
  mix(bank.rotation_frequency());
  mix(bank.a0());
  mix(bank.gain());
  for (int k = 1; k <= bank.harmonics(); ++k) {
    mix(bank.a(k));
    mix(bank.b(k));
  }
  for (int k : bank.rejected()) fnv(h, &k, sizeof k);
  fnv(h, &kind, sizeof kind);
  return h;
}

void check_sample_rate(const OscillatorBank& bank, double fs) {
  const double lo = bank.harmonics() * bank.rotation_frequency() / std::numbers::pi;
  if (!(std::isfinite(fs) && fs > lo))
    throw InvalidParameter("sample_rate",
                           fmt::format("sample_rate = {} is out of range: must be > N*Omega/pi = {} (Nyquist for the "
                                       "highest oscillator, N = {}, Omega = {} rad/s) and finite",
                                       fs, lo, bank.harmonics(), bank.rotation_frequency()));
}

/// Carry a physical state of any N over to N' oscillators (x0 and the common oscillators kept).
Eigen::VectorXd map_state(const Eigen::VectorXd& z, int n_new) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(2 * n_new + 1);
  const Eigen::Index m = std::min<Eigen::Index>(z.size(), out.size());
  out.head(m) = z.head(m);
  return out;
}
}  // namespace

RealtimeFilter::Discretisation RealtimeFilter::discretise(const OscillatorBank& bank, double fs, SampledForm form) {
  check_sample_rate(bank, fs);
  const double h = 1.0 / fs;
  if (form == SampledForm::BlockZeroOrderHold) {
    const int nosc = bank.harmonics(), n = bank.state_size();
    Discretisation d;
    d.kind = Kind::Block;
    d.n = n;
    d.g0 = bank.a0() * h;
    for (int k = 1; k <= nosc; ++k) {
      // e^{J_k h} = rotation by θ = kΩh; ∫₀ʰ e^{J_k s} ds (a_k, b_k)ᵀ = [[sin θ, cos θ − 1], [1 − cos θ, sin θ]] (a, b)ᵀ/(kΩ)
      const double w = k * bank.rotation_frequency(), th = w * h;
      const double c = std::cos(th), sn = std::sin(th);
      const double one_minus_c = 2.0 * std::sin(0.5 * th) * std::sin(0.5 * th);  // 1 − cos θ without cancellation
      d.rc.push_back(c);
      d.rs.push_back(sn);
      d.gx.push_back((sn * bank.a(k) - one_minus_c * bank.b(k)) / w);
      d.gz.push_back((one_minus_c * bank.a(k) + sn * bank.b(k)) / w);
      d.kept.push_back(bank.is_rejected(k) ? 0.0 : 1.0);
      d.wout.push_back(bank.is_rejected(k) ? -bank.gain() : 0.0);
    }
    // internal order (x0, x1..xN, z1..zN) → physical (x0, x1, z1, …): z = P q
    d.basis = Eigen::MatrixXd::Zero(n, n);
    d.basis(0, 0) = 1.0;
    for (int k = 1; k <= nosc; ++k) {
      d.basis(2 * k - 1, k) = 1.0;
      d.basis(2 * k, nosc + k) = 1.0;
    }
    d.basis_inv = d.basis.transpose();
    d.fingerprint = fingerprint(bank, fs, static_cast<int>(d.kind));
    return d;
  }
  const Eigen::MatrixXd a = bank.state_matrix();
  const Eigen::VectorXd b = bank.input_vector();
  const Eigen::RowVectorXd out = -bank.output_vector(), err = bank.error_vector();
  const int n = bank.state_size();
  const ZeroOrderHold zoh = zero_order_hold(a, b, h);

  Discretisation d;
  d.n = n;
  // ---- modal form -------------------------------------------------------------------------------------------
  Eigen::EigenSolver<Eigen::MatrixXd> es(a, true);
  bool ok = es.info() == Eigen::Success;
  std::vector<std::complex<double>> pair_lambda, real_lambda;
  std::vector<Eigen::VectorXcd> pair_vec, real_vec;
  if (ok) {
    const Eigen::VectorXcd& ev = es.eigenvalues();
    const Eigen::MatrixXcd vec = es.eigenvectors();
    for (Eigen::Index i = 0; i < ev.size(); ++i) {
      if (ev(i).imag() == 0.0) {
        real_lambda.push_back(ev(i));
        real_vec.push_back(vec.col(i));
      } else {
        pair_lambda.push_back(ev(i));
        pair_vec.push_back(vec.col(i));
        ++i;  // skip the conjugate (Eigen stores pairs consecutively)
      }
    }
  }
  const int pairs = static_cast<int>(pair_lambda.size()), reals = static_cast<int>(real_lambda.size());
  ok = ok && 2 * pairs + reals == n;
  Eigen::MatrixXd v(n, n), blocks = Eigen::MatrixXd::Zero(n, n);
  if (ok) {
    for (int j = 0; j < pairs; ++j) {
      v.col(j) = pair_vec[j].real();
      v.col(pairs + j) = pair_vec[j].imag();
    }
    for (int j = 0; j < reals; ++j) v.col(2 * pairs + j) = real_vec[j].real();
    // (Eigen's eigenvectors have unit complex norm; the two columns of a pair must share one scale, so no
    // per-column normalisation here.)
    Eigen::FullPivLU<Eigen::MatrixXd> lu(v);
    ok = lu.isInvertible();
    if (ok) {
      d.basis_inv = lu.inverse();
      d.basis = v;
      ok = v.norm() * d.basis_inv.norm() < 1e8;
    }
  }
  if (ok) {
    const Eigen::VectorXd beta = d.basis_inv * b;
    const Eigen::RowVectorXd w = out * v, e = err * v;
    d.pairs = pairs;
    d.reals = reals;
    for (int j = 0; j < pairs; ++j) {
      // block [[σ, ω], [−ω, σ]] in (q1, q2) ⇔ c = q1 + i q2 obeys ċ = μ c + (β1 + iβ2) m, μ = σ − iω
      const std::complex<double> mu = std::conj(pair_lambda[j]);
      const std::complex<double> e_mu = std::exp(mu * h);
      const std::complex<double> g = h * phi_function(1, mu * h) * std::complex<double>(beta(j), beta(pairs + j));
      d.c.push_back(e_mu.real());
      d.s.push_back(-e_mu.imag());
      d.g1.push_back(g.real());
      d.g2.push_back(g.imag());
      d.w1.push_back(w(j));
      d.w2.push_back(w(pairs + j));
      d.e1.push_back(e(j));
      d.e2.push_back(e(pairs + j));
      blocks(j, j) = blocks(pairs + j, pairs + j) = e_mu.real();
      blocks(j, pairs + j) = -e_mu.imag();
      blocks(pairs + j, j) = e_mu.imag();
    }
    for (int j = 0; j < reals; ++j) {
      const double lam = real_lambda[j].real();
      const int i = 2 * pairs + j;
      d.r.push_back(std::exp(lam * h));
      d.gr.push_back(h * phi_function(1, lam * h) * beta(i));
      d.wr.push_back(w(i));
      d.er.push_back(e(i));
      blocks(i, i) = d.r.back();
    }
    // The modal form must reproduce the dense matrix exponential.
    const Eigen::MatrixXd phi_modal = v * blocks * d.basis_inv;
    ok = (phi_modal - zoh.transition).norm() <= 1e-9 * std::max(1.0, zoh.transition.norm());
  }
  if (!ok) {  // dense fallback
    d = Discretisation{};
    d.kind = Kind::Dense;
    d.n = n;
    d.phi.resize(static_cast<std::size_t>(n) * n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) d.phi[static_cast<std::size_t>(i) * n + j] = zoh.transition(i, j);
    d.gamma.assign(zoh.input.data(), zoh.input.data() + n);
    d.out.assign(out.data(), out.data() + n);
    d.err.assign(err.data(), err.data() + n);
    d.basis = Eigen::MatrixXd::Identity(n, n);
    d.basis_inv = d.basis;
  }
  d.fingerprint = fingerprint(bank, fs, static_cast<int>(d.kind));
  return d;
}

RealtimeFilter::RealtimeFilter(const OscillatorBank& controller, double sample_rate, SampledForm form)
    : bank_(controller), sample_rate_(sample_rate), form_(form), disc_(discretise(controller, sample_rate, form)) {
  q_.assign(static_cast<std::size_t>(disc_.n), 0.0);
  q_tmp_ = q_;
}

RealtimeFilter RealtimeFilter::with_couplings(double fs, double omega, int n, double alpha, double beta,
                                              double gain, SampledForm form) {
  return RealtimeFilter(OscillatorBank::with_couplings(omega, n, alpha, beta, gain), fs, form);
}

double RealtimeFilter::advance(double m) noexcept {
  double u0 = 0.0, u1 = 0.0;
  if (disc_.kind == Kind::Block) {
    const int nosc = static_cast<int>(disc_.rc.size());
    double* __restrict x = q_.data() + 1;
    double* __restrict z = x + nosc;
    const double* __restrict kept = disc_.kept.data();
    const double* __restrict wout = disc_.wout.data();
    double e0 = m - q_[0], e1 = 0.0;
    for (int k = 0; k < nosc; ++k) {
      u0 += wout[k] * x[k];
      e1 += kept[k] * x[k];
    }
    const double e = e0 - e1;
    q_[0] += disc_.g0 * e;
    const double* __restrict c = disc_.rc.data();
    const double* __restrict s = disc_.rs.data();
    const double* __restrict gx = disc_.gx.data();
    const double* __restrict gz = disc_.gz.data();
    for (int k = 0; k < nosc; ++k) {
      const double a = x[k], b = z[k];
      x[k] = c[k] * a - s[k] * b + gx[k] * e;
      z[k] = s[k] * a + c[k] * b + gz[k] * e;
    }
    return u0;
  }
  if (disc_.kind == Kind::Modal) {
    const int p = disc_.pairs;
    double* __restrict q1 = q_.data();
    double* __restrict q2 = q1 + p;
    double* __restrict qr = q2 + p;
    const double* __restrict c = disc_.c.data();
    const double* __restrict s = disc_.s.data();
    const double* __restrict g1 = disc_.g1.data();
    const double* __restrict g2 = disc_.g2.data();
    const double* __restrict w1 = disc_.w1.data();
    const double* __restrict w2 = disc_.w2.data();
    // output from the old state: a reduction, kept apart so that the update loop vectorises; four partial sums
    // shorten the dependency chain
    double u2 = 0.0, u3 = 0.0;
    int j = 0;
    for (; j + 1 < p; j += 2) {
      u0 += w1[j] * q1[j];
      u1 += w2[j] * q2[j];
      u2 += w1[j + 1] * q1[j + 1];
      u3 += w2[j + 1] * q2[j + 1];
    }
    if (j < p) {
      u0 += w1[j] * q1[j];
      u1 += w2[j] * q2[j];
    }
    u0 += u2;
    u1 += u3;
    for (int j = 0; j < p; ++j) {  // damped rotation of each modal pair + input
      const double a = q1[j], b = q2[j];
      q1[j] = c[j] * a + s[j] * b + g1[j] * m;
      q2[j] = c[j] * b - s[j] * a + g2[j] * m;
    }
    for (int j = 0; j < disc_.reals; ++j) {
      u0 += disc_.wr[j] * qr[j];
      qr[j] = disc_.r[j] * qr[j] + disc_.gr[j] * m;
    }
    return u0 + u1;
  }
  const int n = disc_.n;
  const double* z = q_.data();
  double* zn = q_tmp_.data();
  for (int j = 0; j < n; ++j) u0 += disc_.out[j] * z[j];
  for (int i = 0; i < n; ++i) {
    const double* row = disc_.phi.data() + static_cast<std::size_t>(i) * n;
    double acc = disc_.gamma[i] * m;
    for (int j = 0; j < n; ++j) acc += row[j] * z[j];
    zn[i] = acc;
  }
  q_.swap(q_tmp_);  // vectors of equal size: swaps pointers only, no allocation
  return u0;
}

double RealtimeFilter::coast_input() const noexcept {
  double m = 0.0;
  if (disc_.kind == Kind::Block) {
    const int nosc = static_cast<int>(disc_.rc.size());
    m = q_[0];
    for (int k = 0; k < nosc; ++k) m += disc_.kept[k] * q_[1 + k];
  } else if (disc_.kind == Kind::Modal) {
    const int p = disc_.pairs;
    for (int j = 0; j < p; ++j) m += disc_.e1[j] * q_[j] + disc_.e2[j] * q_[p + j];
    for (int j = 0; j < disc_.reals; ++j) m += disc_.er[j] * q_[2 * p + j];
  } else {
    for (int j = 0; j < disc_.n; ++j) m += disc_.err[j] * q_[j];
  }
  return m;
}

double RealtimeFilter::step(double measured) noexcept {
  ++samples_;
  if (!std::isfinite(measured)) {
    ++skipped_;
    advance(coast_input());
    return held_;
  }
  held_ = advance(measured);
  return held_;
}

void RealtimeFilter::step_block(std::span<const double> in, std::span<double> out) noexcept {
  const std::size_t n = std::min(in.size(), out.size());
  for (std::size_t i = 0; i < n; ++i) out[i] = step(in[i]);
}

Eigen::VectorXd RealtimeFilter::controller_state() const {
  const Eigen::Map<const Eigen::VectorXd> q(q_.data(), disc_.n);
  return disc_.basis * q;
}

void RealtimeFilter::load_physical(const Eigen::VectorXd& z) {
  const Eigen::VectorXd q = disc_.basis_inv * z;
  q_.assign(q.data(), q.data() + q.size());
  q_tmp_.assign(q_.size(), 0.0);
}

void RealtimeFilter::set_controller_state(const Eigen::VectorXd& z) {
  if (z.size() != disc_.n)
    throw InvalidParameter("state", fmt::format("state has {} entries: must have 2N+1 = {}", z.size(), disc_.n));
  if (!z.allFinite()) throw InvalidParameter("state", "state: every entry must be finite");
  load_physical(z);
}

void RealtimeFilter::reconfigure(const OscillatorBank& controller, double sample_rate) {
  reconfigure(controller, sample_rate, form_);
}

void RealtimeFilter::reconfigure(const OscillatorBank& controller, double sample_rate, SampledForm form) {
  Discretisation d = discretise(controller, sample_rate, form);  // may throw: filter unchanged
  Eigen::VectorXd z = map_state(controller_state(), controller.harmonics());
  if (controller.rejected() == bank_.rejected() && controller.gain() != bank_.gain()) {
    const double scale = bank_.gain() / controller.gain();  // u = −K Σ_rej x_k continuous
    for (int k : controller.rejected()) {
      z(2 * k - 1) *= scale;
      z(2 * k) *= scale;
    }
  }
  const Eigen::VectorXd q = d.basis_inv * z;
  std::vector<double> qv(q.data(), q.data() + q.size()), tmp(qv.size(), 0.0);
  OscillatorBank bank = controller;
  // commit (no throwing operations below)
  bank_ = std::move(bank);
  sample_rate_ = sample_rate;
  form_ = form;
  disc_ = std::move(d);
  q_.swap(qv);
  q_tmp_.swap(tmp);
}

void RealtimeFilter::set_gain(double gain) { reconfigure(bank_.with_gain(gain), sample_rate_); }

void RealtimeFilter::reset() noexcept {
  std::fill(q_.begin(), q_.end(), 0.0);
  std::fill(q_tmp_.begin(), q_tmp_.end(), 0.0);
  held_ = 0.0;
  skipped_ = 0;
  samples_ = 0;
}

std::size_t RealtimeFilter::state_size() const noexcept { return kHeader + q_.size() + static_cast<std::size_t>(disc_.n); }

void RealtimeFilter::save_state(std::span<double> out) const {
  if (out.size() < state_size())
    throw InvalidParameter("state", fmt::format("state buffer has {} entries: must have at least state_size() = {}",
                                                out.size(), state_size()));
  out[0] = kMagic;
  out[1] = kLayoutVersion;
  out[2] = bank_.harmonics();
  out[3] = static_cast<double>(q_.size());
  out[4] = static_cast<double>(disc_.fingerprint >> 32);
  out[5] = static_cast<double>(disc_.fingerprint & 0xffffffffULL);
  out[6] = held_;
  out[7] = static_cast<double>(skipped_);
  out[8] = static_cast<double>(samples_);
  out[9] = disc_.n;
  std::copy(q_.begin(), q_.end(), out.begin() + kHeader);
  const Eigen::VectorXd z = controller_state();
  std::copy(z.data(), z.data() + z.size(), out.begin() + kHeader + q_.size());
}

std::vector<double> RealtimeFilter::save_state() const {
  std::vector<double> v(state_size());
  save_state(v);
  return v;
}

void RealtimeFilter::restore_state(std::span<const double> in) {
  auto bad = [](const std::string& why) { throw InvalidParameter("state", "state buffer is not a saved filter state: " + why); };
  if (in.size() < kHeader) bad(fmt::format("{} entries, the header alone has {}", in.size(), kHeader));
  if (in[0] != kMagic) bad("wrong magic number");
  if (in[1] != kLayoutVersion) bad(fmt::format("layout version {} (this build reads {})", in[1], kLayoutVersion));
  for (double x : in)
    if (!std::isfinite(x)) bad("non-finite entry");
  const double n_osc = in[2], ni = in[3], np = in[9];
  if (n_osc < 1 || n_osc != std::floor(n_osc) || np != 2 * n_osc + 1 || ni < 0 || ni != std::floor(ni) ||
      in.size() != kHeader + static_cast<std::size_t>(ni) + static_cast<std::size_t>(np))
    bad(fmt::format("inconsistent sizes (N = {}, internal {}, physical {}, total {})", n_osc, ni, np, in.size()));
  for (int i = 6; i <= 8; ++i)
    if (i > 6 && (in[i] < 0 || in[i] != std::floor(in[i]))) bad("negative or fractional counter");
  const std::uint64_t fp = (static_cast<std::uint64_t>(in[4]) << 32) | static_cast<std::uint64_t>(in[5]);
  std::vector<double> qv;
  if (fp == disc_.fingerprint && static_cast<std::size_t>(ni) == q_.size()) {
    qv.assign(in.begin() + kHeader, in.begin() + kHeader + static_cast<std::ptrdiff_t>(ni));  // bit for bit
  } else {
    const auto off = static_cast<std::ptrdiff_t>(kHeader + static_cast<std::size_t>(ni));
    Eigen::VectorXd z(static_cast<Eigen::Index>(np));
    for (Eigen::Index i = 0; i < z.size(); ++i) z(i) = in[off + i];
    const Eigen::VectorXd q = disc_.basis_inv * map_state(z, bank_.harmonics());
    qv.assign(q.data(), q.data() + q.size());
  }
  q_.swap(qv);
  held_ = in[6];
  skipped_ = static_cast<std::uint64_t>(in[7]);
  samples_ = static_cast<std::uint64_t>(in[8]);
}

Eigen::MatrixXd RealtimeFilter::transition_matrix() const {
  if (disc_.kind == Kind::Block) {  // Φ = R − G c_eᵀ in the physical coordinates
    const Eigen::Index n = disc_.n;
    Eigen::MatrixXd r = Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd g = input_vector();
    Eigen::RowVectorXd ce = Eigen::RowVectorXd::Zero(n);
    ce(0) = 1.0;
    for (std::size_t k = 0; k < disc_.rc.size(); ++k) {
      const auto i = static_cast<Eigen::Index>(2 * k + 1);
      r(i, i) = r(i + 1, i + 1) = disc_.rc[k];
      r(i, i + 1) = -disc_.rs[k];
      r(i + 1, i) = disc_.rs[k];
      ce(i) = disc_.kept[k];
    }
    return r - g * ce;
  }
  if (disc_.kind == Kind::Dense) {
    Eigen::MatrixXd phi(disc_.n, disc_.n);
    for (int i = 0; i < disc_.n; ++i)
      for (int j = 0; j < disc_.n; ++j) phi(i, j) = disc_.phi[static_cast<std::size_t>(i) * disc_.n + j];
    return phi;
  }
  const int p = disc_.pairs;
  Eigen::MatrixXd blocks = Eigen::MatrixXd::Zero(disc_.n, disc_.n);
  for (int j = 0; j < p; ++j) {
    blocks(j, j) = blocks(p + j, p + j) = disc_.c[j];
    blocks(j, p + j) = disc_.s[j];
    blocks(p + j, j) = -disc_.s[j];
  }
  for (int j = 0; j < disc_.reals; ++j) blocks(2 * p + j, 2 * p + j) = disc_.r[j];
  return disc_.basis * blocks * disc_.basis_inv;
}

Eigen::VectorXd RealtimeFilter::input_vector() const {
  if (disc_.kind == Kind::Block) {
    Eigen::VectorXd g(disc_.n);
    g(0) = disc_.g0;
    for (std::size_t k = 0; k < disc_.rc.size(); ++k) {
      g(static_cast<Eigen::Index>(2 * k + 1)) = disc_.gx[k];
      g(static_cast<Eigen::Index>(2 * k + 2)) = disc_.gz[k];
    }
    return g;
  }
  if (disc_.kind == Kind::Dense) return Eigen::Map<const Eigen::VectorXd>(disc_.gamma.data(), disc_.n);
  Eigen::VectorXd g(disc_.n);
  const int p = disc_.pairs;
  for (int j = 0; j < p; ++j) {
    g(j) = disc_.g1[j];
    g(p + j) = disc_.g2[j];
  }
  for (int j = 0; j < disc_.reals; ++j) g(2 * p + j) = disc_.gr[j];
  return disc_.basis * g;
}

Eigen::RowVectorXd RealtimeFilter::output_vector() const {
  if (disc_.kind == Kind::Block) {
    Eigen::RowVectorXd w = Eigen::RowVectorXd::Zero(disc_.n);
    for (std::size_t k = 0; k < disc_.rc.size(); ++k) w(static_cast<Eigen::Index>(2 * k + 1)) = disc_.wout[k];
    return w;
  }
  if (disc_.kind == Kind::Dense) return Eigen::Map<const Eigen::RowVectorXd>(disc_.out.data(), disc_.n);
  Eigen::RowVectorXd w(disc_.n);
  const int p = disc_.pairs;
  for (int j = 0; j < p; ++j) {
    w(j) = disc_.w1[j];
    w(p + j) = disc_.w2[j];
  }
  for (int j = 0; j < disc_.reals; ++j) w(2 * p + j) = disc_.wr[j];
  return w * disc_.basis_inv;
}

}  // namespace afmkit::control
