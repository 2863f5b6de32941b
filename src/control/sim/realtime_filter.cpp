#include "afmkit/control/realtime_filter.hpp"

#include <cmath>
#include <cstring>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/control/discretisation.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "pair_kernels.hpp"

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
    d.offset = 1;  // internal state = physical (x0, x1, z1, …, xN, zN)
    d.pairs = nosc;
    d.g0 = bank.a0() * h;
    for (int k = 1; k <= nosc; ++k) {
      // e^{J_k h} = rotation by θ = kΩh: x' = cos θ x − sin θ z, z' = sin θ x + cos θ z;
      // ∫₀ʰ e^{J_k s} ds (a_k, b_k)ᵀ = [[sin θ, cos θ − 1], [1 − cos θ, sin θ]] (a_k, b_k)ᵀ / (kΩ)
      const double w = k * bank.rotation_frequency(), th = w * h;
      const double c = std::cos(th), sn = std::sin(th);
      const double one_minus_c = 2.0 * std::sin(0.5 * th) * std::sin(0.5 * th);  // 1 − cos θ without cancellation
      d.c.insert(d.c.end(), {c, c});
      d.s.insert(d.s.end(), {-sn, sn});
      d.g.insert(d.g.end(), {(sn * bank.a(k) - one_minus_c * bank.b(k)) / w, (one_minus_c * bank.a(k) + sn * bank.b(k)) / w});
      d.kw.insert(d.kw.end(), {bank.is_rejected(k) ? 0.0 : 1.0, bank.is_rejected(k) ? -bank.gain() : 0.0});
    }
    d.basis = Eigen::MatrixXd::Identity(n, n);
    d.basis_inv = d.basis;
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
      v.col(2 * j) = pair_vec[j].real();
      v.col(2 * j + 1) = pair_vec[j].imag();
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
    d.w.assign(w.data(), w.data() + n);
    d.e.assign(e.data(), e.data() + n);
    for (int j = 0; j < pairs; ++j) {
      // block [[σ, ω], [−ω, σ]] in (q1, q2) ⇔ c = q1 + i q2 obeys ċ = μ c + (β1 + iβ2) m, μ = σ − iω;
      // e^{μh} = P − iS ⇒ q1' = P q1 + S q2, q2' = P q2 − S q1
      const std::complex<double> mu = std::conj(pair_lambda[j]);
      const std::complex<double> e_mu = std::exp(mu * h);
      const std::complex<double> g = h * phi_function(1, mu * h) * std::complex<double>(beta(2 * j), beta(2 * j + 1));
      const double pp = e_mu.real(), ss = -e_mu.imag();
      d.c.insert(d.c.end(), {pp, pp});
      d.s.insert(d.s.end(), {ss, -ss});
      d.g.insert(d.g.end(), {g.real(), g.imag()});
      blocks(2 * j, 2 * j) = blocks(2 * j + 1, 2 * j + 1) = pp;
      blocks(2 * j, 2 * j + 1) = ss;
      blocks(2 * j + 1, 2 * j) = -ss;
    }
    for (int j = 0; j < reals; ++j) {
      const double lam = real_lambda[j].real();
      const int i = 2 * pairs + j;
      d.r.push_back(std::exp(lam * h));
      d.gr.push_back(h * phi_function(1, lam * h) * beta(i));
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
  const Discretisation& d = disc_;
  double* q = q_.data();
  if (d.kind == Kind::Modal) {
    const int p = d.pairs, np = 2 * p;
    // output from the old state, damped rotation of every modal pair, then the real modes
    double u = detail::rotate_pairs_dot(q, d.c.data(), d.s.data(), d.g.data(), d.w.data(), m, p);
    for (int j = 0; j < d.reals; ++j) {
      const double x = q[np + j];
      u += d.w[np + j] * x;
      q[np + j] = d.r[j] * x + d.gr[j] * m;
    }
    return u;
  }
  if (d.kind == Kind::Block) {
    double kept_sum, u;
    detail::accumulate_first(d.kw.data(), q + 1, d.pairs, kept_sum, u);  // Σ_kept x_k, −K Σ_rej x_k
    const double e = m - q[0] - kept_sum;                               // e_n, held over the step
    q[0] += d.g0 * e;
    detail::rotate_pairs(q + 1, d.c.data(), d.s.data(), d.g.data(), e, d.pairs);
    return u;
  }
  const int n = d.n;
  double* zn = q_tmp_.data();
  double u = 0.0;
  for (int j = 0; j < n; ++j) u += d.out[j] * q[j];
  for (int i = 0; i < n; ++i) {
    const double* row = d.phi.data() + static_cast<std::size_t>(i) * n;
    double acc = d.gamma[i] * m;
    for (int j = 0; j < n; ++j) acc += row[j] * q[j];
    zn[i] = acc;
  }
  q_.swap(q_tmp_);  // vectors of equal size: swaps pointers only, no allocation
  return u;
}

double RealtimeFilter::coast_input() const noexcept {
  const Discretisation& d = disc_;
  const double* q = q_.data();
  if (d.kind == Kind::Modal) {
    double m = detail::dot_pairs(d.e.data(), q, d.pairs);
    for (int j = 0; j < d.reals; ++j) m += d.e[2 * d.pairs + j] * q[2 * d.pairs + j];
    return m;
  }
  if (d.kind == Kind::Block) {
    double kept_sum, u;
    detail::accumulate_first(d.kw.data(), q + 1, d.pairs, kept_sum, u);
    return q[0] + kept_sum;
  }
  double m = 0.0;
  for (int j = 0; j < d.n; ++j) m += d.err[j] * q[j];
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
  const Discretisation& d = disc_;
  if (d.kind == Kind::Dense) {
    Eigen::MatrixXd phi(d.n, d.n);
    for (int i = 0; i < d.n; ++i)
      for (int j = 0; j < d.n; ++j) phi(i, j) = d.phi[static_cast<std::size_t>(i) * d.n + j];
    return phi;
  }
  // internal transition: 2×2 blocks (c, s) from `offset`, real modes after them (modal) or x0 (block)
  Eigen::MatrixXd t = Eigen::MatrixXd::Identity(d.n, d.n);
  for (int j = 0; j < d.pairs; ++j) {
    const int i = d.offset + 2 * j;
    t(i, i) = d.c[2 * j];
    t(i, i + 1) = d.s[2 * j];
    t(i + 1, i + 1) = d.c[2 * j + 1];
    t(i + 1, i) = d.s[2 * j + 1];
  }
  for (int j = 0; j < d.reals; ++j) t(2 * d.pairs + j, 2 * d.pairs + j) = d.r[j];
  if (d.kind == Kind::Block) {  // the held error e = m − c_eᵀ z couples every state: Φ = R − Γ c_eᵀ
    Eigen::RowVectorXd ce = Eigen::RowVectorXd::Zero(d.n);
    ce(0) = 1.0;
    for (int j = 0; j < d.pairs; ++j) ce(1 + 2 * j) = d.kw[2 * j];
    return t - input_vector() * ce;
  }
  return d.basis * t * d.basis_inv;
}

Eigen::VectorXd RealtimeFilter::input_vector() const {
  const Discretisation& d = disc_;
  if (d.kind == Kind::Dense) return Eigen::Map<const Eigen::VectorXd>(d.gamma.data(), d.n);
  Eigen::VectorXd g(d.n);
  if (d.kind == Kind::Block) g(0) = d.g0;
  for (int j = 0; j < 2 * d.pairs; ++j) g(d.offset + j) = d.g[j];
  for (int j = 0; j < d.reals; ++j) g(2 * d.pairs + j) = d.gr[j];
  return d.basis * g;
}

Eigen::RowVectorXd RealtimeFilter::output_vector() const {
  const Discretisation& d = disc_;
  if (d.kind == Kind::Dense) return Eigen::Map<const Eigen::RowVectorXd>(d.out.data(), d.n);
  if (d.kind == Kind::Block) {
    Eigen::RowVectorXd w = Eigen::RowVectorXd::Zero(d.n);
    for (int j = 0; j < d.pairs; ++j) w(1 + 2 * j) = d.kw[2 * j + 1];
    return w;
  }
  return Eigen::Map<const Eigen::RowVectorXd>(d.w.data(), d.n) * d.basis_inv;
}

}  // namespace afmkit::control
