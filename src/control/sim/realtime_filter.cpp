#include "afmkit/control/realtime_filter.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/control/discretisation.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "modal_kernel.hpp"
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
  const bool block = form == SampledForm::BlockZeroOrderHold;
  const int max_n = block ? kMaxHarmonicsBlock : kMaxHarmonics;
  if (bank.harmonics() > max_n)
    throw InvalidParameter("harmonics",
                           fmt::format("harmonics = {} is out of range: must be an integer in [1, {}] for the {} form "
                                       "(set-up cost {})",
                                       bank.harmonics(), max_n, block ? "block zero-order-hold" : "zero-order-hold",
                                       block ? "O(N)" : "O(N^2): about 4 s at the upper end"));
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
    d.fingerprint = fingerprint(bank, fs, static_cast<int>(d.kind));
    return d;
  }
  bool ok = false;
  Discretisation d = modal(bank, fs, ok);
  if (!ok) {  // dense fallback: O(N³) set-up, O(N²) memory, so only for small N
    if (bank.harmonics() > kMaxDenseHarmonics)
      throw InvalidParameter(
          "harmonics",
          fmt::format("harmonics = {}: these couplings make the modal basis of the zero-order-hold form "
                      "ill-conditioned or defective (or a0 = 0), which needs the dense O(N^3) fallback, allowed "
                      "only for harmonics in [1, {}]; use the block form (BlockZeroOrderHold) or other couplings",
                      bank.harmonics(), kMaxDenseHarmonics));
    const Eigen::RowVectorXd out = -bank.output_vector(), err = bank.error_vector();
    const int n = bank.state_size();
    const ZeroOrderHold zoh = zero_order_hold(bank.state_matrix(), bank.input_vector(), h);
    d = Discretisation{};
    d.kind = Kind::Dense;
    d.n = n;
    d.phi.resize(static_cast<std::size_t>(n) * n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) d.phi[static_cast<std::size_t>(i) * n + j] = zoh.transition(i, j);
    d.gamma.assign(zoh.input.data(), zoh.input.data() + n);
    d.out.assign(out.data(), out.data() + n);
    d.err.assign(err.data(), err.data() + n);
  }
  d.fingerprint = fingerprint(bank, fs, static_cast<int>(d.kind));
  return d;
}

// ---- modal zero-order hold without N×N matrices (header comment; docs/theory-control.md#oscillator-bank) ------------------------------------
namespace {
using cplx = std::complex<double>;

struct BankView {  // the couplings in flat arrays (OscillatorBank::a() is bounds-checked)
  int n = 0;
  double omega = 0, a0 = 0, gain = 0, b_norm = 0, a_norm = 0;
  std::vector<double> a, b;
  std::vector<char> kept;
  explicit BankView(const OscillatorBank& bank)
      : n(bank.harmonics()), omega(bank.rotation_frequency()), a0(bank.a0()), gain(bank.gain()) {
    double b2 = a0 * a0, a2 = 0.0;
    for (int k = 1; k <= n; ++k) {
      a.push_back(bank.a(k));
      b.push_back(bank.b(k));
      kept.push_back(bank.is_rejected(k) ? 0 : 1);
      b2 += a.back() * a.back() + b.back() * b.back();
      a2 += 2.0 * (k * omega) * (k * omega);
    }
    b_norm = std::sqrt(b2);
    double ce2 = 1.0;
    for (char c : kept) ce2 += c;
    a_norm = std::sqrt(a2) + b_norm * std::sqrt(ce2);  // ≥ ‖A0 − b c_eᵀ‖_F
  }
};

/// One O(N) pass at λ over v = (λ − A0)⁻¹ b and u = (λ − A0)⁻ᵀ c_e (block `skip` left out):
/// D = 1 + c_eᵀ v (D(λ) = 0 at an eigenvalue, eq. 18), uᵀv = −D'(λ), ‖v‖², ‖u‖², c_rᵀ v.
struct ModePass {
  cplx d, utv, rej;
  double v2 = 0, u2 = 0;
};
ModePass mode_pass(const BankView& bv, cplx l, int skip = 0) {
  ModePass p;
  const cplx r0 = 1.0 / l, v0 = bv.a0 * r0;
  p.d = 1.0 + v0;
  p.utv = r0 * v0;
  p.v2 = std::norm(v0);
  p.u2 = std::norm(r0);
  const cplx l2 = l * l;
  for (int k = 1; k <= bv.n; ++k) {
    if (k == skip) continue;
    const double kw = k * bv.omega, ak = bv.a[k - 1], bk = bv.b[k - 1];
    const cplx den = l2 + kw * kw;
    const cplx inv = std::conj(den) / std::norm(den);
    const cplx vx = (l * ak - kw * bk) * inv, vz = (kw * ak + l * bk) * inv;
    p.v2 += std::norm(vx) + std::norm(vz);
    if (bv.kept[k - 1]) {
      const cplx ux = l * inv, uz = -kw * inv;
      p.d += vx;
      p.utv += ux * vx + uz * vz;
      p.u2 += std::norm(ux) + std::norm(uz);
    } else {
      p.rej += vx;
    }
  }
  return p;
}

/// Σ_i ((λ − A0)⁻ᵀ c_e)_i z_i, O(N).
cplx left_dot(const BankView& bv, cplx l, const double* z) {
  cplx acc = z[0] / l;
  const cplx l2 = l * l;
  for (int k = 1; k <= bv.n; ++k) {
    if (!bv.kept[k - 1]) continue;
    const double kw = k * bv.omega;
    const cplx den = l2 + kw * kw;
    acc += (l * z[2 * k - 1] - kw * z[2 * k]) * (std::conj(den) / std::norm(den));
  }
  return acc;
}

/// z += Re(s (λ − A0)⁻¹ b), O(N).
void add_right(const BankView& bv, cplx l, cplx s, double* z) {
  z[0] += (s * bv.a0 / l).real();
  const cplx l2 = l * l;
  for (int k = 1; k <= bv.n; ++k) {
    const double kw = k * bv.omega, ak = bv.a[k - 1], bk = bv.b[k - 1];
    const cplx den = l2 + kw * kw;
    const cplx f = s * std::conj(den) / std::norm(den);
    z[2 * k - 1] += (f * (l * ak - kw * bk)).real();
    z[2 * k] += (f * (kw * ak + l * bk)).real();
  }
}
}  // namespace

RealtimeFilter::Discretisation RealtimeFilter::modal(const OscillatorBank& bank, double fs, bool& ok) {
  ok = false;
  Discretisation d;
  d.kind = Kind::Modal;
  d.n = bank.state_size();
  if (bank.a0() == 0.0) return d;  // the x0 mode is then λ = 0 with a zero row: not handled here
  std::vector<cplx> ev;
  try {
    ev = bank_eigenvalues(bank);
  } catch (const NumericalFailure&) {
    return d;
  }
  if (static_cast<int>(ev.size()) != d.n) return d;
  const BankView bv(bank);
  const double h = 1.0 / fs, tol = 1e-10 * bv.omega * (bv.n + 1);
  std::vector<Discretisation::Mode> pairs, reals;
  int negative = 0;
  for (cplx l : ev) {
    Discretisation::Mode m;
    const double kq = std::round(std::abs(l.imag()) / bv.omega);
    if (l.real() == 0.0 && kq >= 1 && kq <= bv.n && kq * bv.omega == std::abs(l.imag()) &&
        !bv.kept[static_cast<std::size_t>(kq) - 1]) {  // exact mode ±ikΩ of a rejected oscillator
      if (l.imag() < 0) continue;
      m.lambda = l;
      m.rejected = static_cast<int>(kq);
      pairs.push_back(m);
      continue;
    }
    if (std::abs(l.imag()) <= tol) l = cplx(l.real(), 0.0);
    if (l.imag() < 0) {
      ++negative;
      continue;
    }
    m.lambda = l;
    (l.imag() == 0.0 ? reals : pairs).push_back(m);
  }
  int aberth_pairs = 0;
  for (const auto& m : pairs) aberth_pairs += m.rejected == 0;
  if (negative != aberth_pairs || 2 * static_cast<int>(pairs.size()) + static_cast<int>(reals.size()) != d.n) return d;
  d.modes = std::move(pairs);
  d.pairs = static_cast<int>(d.modes.size());
  d.reals = static_cast<int>(reals.size());
  d.modes.insert(d.modes.end(), reals.begin(), reals.end());

  double v_frob2 = 0.0, u_frob2 = 0.0, worst_residual = 0.0;
  for (int j = 0; j < d.pairs + d.reals; ++j) {
    Discretisation::Mode& m = d.modes[static_cast<std::size_t>(j)];
    const bool pair = j < d.pairs;
    cplx beta, w, e;
    double u2;
    if (m.rejected) {
      // v̂ = (1, −i)/√2 in block k; û = (1, i)/√2 − s (λ − A0)⁻ᵀ c_e with s = ûᵀb = (a_k + i b_k)/(√2 D(ikΩ))
      const ModePass p = mode_pass(bv, m.lambda, m.rejected);
      const cplx s = cplx(bv.a[m.rejected - 1], bv.b[m.rejected - 1]) / (std::sqrt(2.0) * p.d);
      m.u_scale = s;
      beta = s;
      w = -bv.gain / std::sqrt(2.0);
      e = 0.0;
      u2 = 1.0 + std::norm(s) * p.u2;
    } else {
      ModePass p = mode_pass(bv, m.lambda);
      // one Newton step on D (D' = −uᵀv), kept if it reduces |D|
      cplx l1 = m.lambda + p.d / p.utv;
      if (!pair) l1 = cplx(l1.real(), 0.0);
      const ModePass p1 = mode_pass(bv, l1);
      if (std::abs(p1.d) < std::abs(p.d)) {
        m.lambda = l1;
        p = p1;
      }
      const double vn = std::sqrt(p.v2);
      m.v_scale = 1.0 / vn;
      m.u_scale = vn / p.utv;
      beta = (p.d - 1.0) * m.u_scale;  // ûᵀb = u_scale c_eᵀ(λ − A0)⁻¹ b
      w = -bv.gain * p.rej * m.v_scale;
      e = (p.d - 1.0) * m.v_scale;
      u2 = p.u2 * std::norm(m.u_scale);
      worst_residual = std::max(worst_residual, std::abs(p.d) * bv.b_norm * m.v_scale / bv.a_norm);  // ‖(A − λ)v̂‖/‖A‖
    }
    v_frob2 += 1.0;
    if (pair) {
      u_frob2 += 4.0 * u2;
      const cplx mu = std::conj(m.lambda), e_mu = std::exp(mu * h);
      const cplx g = h * phi_function(1, mu * h) * 2.0 * std::conj(beta);
      d.c.insert(d.c.end(), {e_mu.real(), e_mu.real()});
      d.s.insert(d.s.end(), {-e_mu.imag(), e_mu.imag()});
      d.g.insert(d.g.end(), {g.real(), g.imag()});
      d.w.insert(d.w.end(), {w.real(), w.imag()});
      d.e.insert(d.e.end(), {e.real(), e.imag()});
    } else {
      u_frob2 += u2;
      const double lam = m.lambda.real();
      d.r.push_back(std::exp(lam * h));
      d.gr.push_back(h * phi_function(1, lam * h) * beta.real());
      d.w.push_back(w.real());
      d.e.push_back(e.real());
    }
  }
  // the kernel's layout: mode j (pairs, then reals) in group j/4, lane j%4 (modal_kernel.hpp)
  const int modes = d.pairs + d.reals;
  d.groups = (modes + 3) / 4;
  d.packed.assign(static_cast<std::size_t>(d.groups) * detail::kGroupDoubles, 0.0);
  for (int j = 0; j < modes; ++j) {
    double* g = d.packed.data() + static_cast<std::size_t>(j / 4) * detail::kGroupDoubles + j % 4;
    auto put = [&](detail::Coef k, double v) { g[4 * k] = v; };
    if (j < d.pairs) {  // c = c1 = c2 and s = s2 = −s1 exactly (a damped rotation): q1 ← c q1 − s q2, q2 ← c q2 + s q1
      put(detail::kC, d.c[2 * j]), put(detail::kS, d.s[2 * j + 1]);
      put(detail::kG1, d.g[2 * j]), put(detail::kG2, d.g[2 * j + 1]);
      put(detail::kW1, d.w[2 * j]), put(detail::kW2, d.w[2 * j + 1]);
      put(detail::kE1, d.e[2 * j]), put(detail::kE2, d.e[2 * j + 1]);
    } else {  // a real mode in q1 (its q2, s, g2, w2, e2 stay 0)
      const int i = j - d.pairs;
      put(detail::kC, d.r[i]), put(detail::kG1, d.gr[i]);
      put(detail::kW1, d.w[2 * d.pairs + i]), put(detail::kE1, d.e[2 * d.pairs + i]);
    }
  }
  const double cond = std::sqrt(v_frob2 * u_frob2);  // ‖V‖_F ‖V⁻¹‖_F, as for a dense eigenvector basis
  ok = std::isfinite(cond) && cond < 1e8 && cond * worst_residual < 1e-10;
  for (const auto* v : {&d.c, &d.s, &d.g, &d.w, &d.e, &d.r, &d.gr})
    for (double x : *v) ok = ok && std::isfinite(x);
  return d;
}

Eigen::VectorXd RealtimeFilter::to_physical(const OscillatorBank& bank, const Discretisation& d, const double* q) {
  if (d.kind != Kind::Modal) return Eigen::Map<const Eigen::VectorXd>(q, d.n);
  const BankView bv(bank);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(d.n);
  for (int j = 0; j < d.pairs + d.reals; ++j) {
    const Discretisation::Mode& m = d.modes[static_cast<std::size_t>(j)];
    const cplx c = j < d.pairs ? cplx(q[2 * j], -q[2 * j + 1]) : cplx(q[d.pairs + j], 0.0);  // z += Re(v̂ c)
    if (c == 0.0) continue;
    if (m.rejected) {
      z(2 * m.rejected - 1) += (c / std::sqrt(2.0)).real();
      z(2 * m.rejected) += (cplx(0.0, -1.0) * c / std::sqrt(2.0)).real();
    } else {
      add_right(bv, m.lambda, m.v_scale * c, z.data());
    }
  }
  return z;
}

Eigen::VectorXd RealtimeFilter::to_internal(const OscillatorBank& bank, const Discretisation& d,
                                            const Eigen::VectorXd& z) {
  if (d.kind != Kind::Modal) return z;
  const BankView bv(bank);
  Eigen::VectorXd q(d.n);
  for (int j = 0; j < d.pairs + d.reals; ++j) {
    const Discretisation::Mode& m = d.modes[static_cast<std::size_t>(j)];
    cplx p = left_dot(bv, m.lambda, z.data());  // ûᵀz
    if (m.rejected) p = cplx(z(2 * m.rejected - 1), z(2 * m.rejected)) / std::sqrt(2.0) - m.u_scale * p;
    else p *= m.u_scale;
    if (j < d.pairs) {  // q1 + i q2 = 2 conj(ûᵀz)
      q(2 * j) = 2.0 * p.real();
      q(2 * j + 1) = -2.0 * p.imag();
    } else {
      q(d.pairs + j) = p.real();
    }
  }
  return q;
}

RealtimeFilter::RealtimeFilter(const OscillatorBank& controller, double sample_rate, SampledForm form)
    : bank_(controller), sample_rate_(sample_rate), form_(form), disc_(discretise(controller, sample_rate, form)) {
  q_ = pack(disc_, std::vector<double>(static_cast<std::size_t>(disc_.n), 0.0).data());
  q_tmp_.assign(static_cast<std::size_t>(disc_.n), 0.0);
  set_vectorisation(Vectorisation::Auto);
}

std::vector<double> RealtimeFilter::pack(const Discretisation& d, const double* internal) {
  if (d.kind != Kind::Modal) return std::vector<double>(internal, internal + d.n);
  std::vector<double> q(static_cast<std::size_t>(8 * d.groups), 0.0);
  const std::size_t second = static_cast<std::size_t>(4 * d.groups);  // q2 of lane j at second + j
  for (int j = 0; j < d.pairs; ++j) {
    q[static_cast<std::size_t>(j)] = internal[2 * j];
    q[second + static_cast<std::size_t>(j)] = internal[2 * j + 1];
  }
  for (int i = 0; i < d.reals; ++i) q[static_cast<std::size_t>(d.pairs + i)] = internal[2 * d.pairs + i];
  return q;
}

std::vector<double> RealtimeFilter::internal_state() const {
  const Discretisation& d = disc_;
  if (d.kind != Kind::Modal) return q_;
  std::vector<double> z(static_cast<std::size_t>(d.n));
  const std::size_t second = static_cast<std::size_t>(4 * d.groups);
  for (int j = 0; j < d.pairs; ++j) {
    z[static_cast<std::size_t>(2 * j)] = q_[static_cast<std::size_t>(j)];
    z[static_cast<std::size_t>(2 * j + 1)] = q_[second + static_cast<std::size_t>(j)];
  }
  for (int i = 0; i < d.reals; ++i)
    z[static_cast<std::size_t>(2 * d.pairs + i)] = q_[static_cast<std::size_t>(d.pairs + i)];
  return z;
}

RealtimeFilter RealtimeFilter::with_couplings(double fs, double omega, int n, double alpha, double beta,
                                              double gain, SampledForm form) {
  return RealtimeFilter(OscillatorBank::with_couplings(omega, n, alpha, beta, gain), fs, form);
}

double RealtimeFilter::advance(double m) noexcept {
  const Discretisation& d = disc_;
  double* q = q_.data();
  if (d.kind == Kind::Block) {  // (the modal form runs in run_modal)
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
  if (d.kind == Kind::Block) {  // (the modal form coasts in run_modal)
    double kept_sum, u;
    detail::accumulate_first(d.kw.data(), q + 1, d.pairs, kept_sum, u);
    return q[0] + kept_sum;
  }
  double m = 0.0;
  for (int j = 0; j < d.n; ++j) m += d.err[j] * q[j];
  return m;
}

void RealtimeFilter::run_modal(const double* in, double* out, std::size_t n) noexcept {
  detail::ModalRun run{disc_.packed.data(), disc_.groups, input_limit_, held_, skipped_};
  if (n == 1) detail::modal_block_portable(run, q_.data(), in, out, 1);  // step(): inlined, state in memory
  else detail::modal_block_dispatch(path_ == Vectorisation::Avx512 ? detail::ModalPath::Avx512
                                    : path_ == Vectorisation::Avx2 ? detail::ModalPath::Avx2
                                                                   : detail::ModalPath::Portable,
                                    run, q_.data(), in, out, n);
  held_ = run.held;
  skipped_ = run.skipped;
  samples_ += n;
}

double RealtimeFilter::step(double measured) noexcept {
  if (disc_.kind == Kind::Modal) {
    double u;
    run_modal(&measured, &u, 1);
    return u;
  }
  ++samples_;
  if (!(std::abs(measured) <= input_limit_)) {  // NaN, ±inf and |m| > input_limit(): skipped
    ++skipped_;
    advance(coast_input());
    return held_;
  }
  held_ = advance(measured);
  return held_;
}

void RealtimeFilter::step_block(std::span<const double> in, std::span<double> out) noexcept {
  const std::size_t n = std::min(in.size(), out.size());
  if (disc_.kind == Kind::Modal) {
    run_modal(in.data(), out.data(), n);
    return;
  }
  for (std::size_t i = 0; i < n; ++i) out[i] = step(in[i]);
}

Eigen::VectorXd RealtimeFilter::controller_state() const {
  return to_physical(bank_, disc_, internal_state().data());
}

void RealtimeFilter::load_physical(const Eigen::VectorXd& z) {
  const Eigen::VectorXd q = to_internal(bank_, disc_, z);
  q_ = pack(disc_, q.data());
  q_tmp_.assign(static_cast<std::size_t>(disc_.n), 0.0);
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
  const Eigen::VectorXd q = to_internal(controller, d, z);
  std::vector<double> qv = pack(d, q.data()), tmp(static_cast<std::size_t>(d.n), 0.0);
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

bool RealtimeFilter::vectorisation_available(Vectorisation v) noexcept {
  switch (v) {
    case Vectorisation::Avx512: return detail::modal_path_available(detail::ModalPath::Avx512);
    case Vectorisation::Avx2: return detail::modal_path_available(detail::ModalPath::Avx2);
    default: return true;
  }
}

void RealtimeFilter::set_vectorisation(Vectorisation v) noexcept {
  // Auto or an unavailable build: the widest available one not wider than asked (Auto: the widest of all)
  if (v == Vectorisation::Auto) v = Vectorisation::Avx512;
  if (v == Vectorisation::Avx512 && !vectorisation_available(v)) v = Vectorisation::Avx2;
  if (v == Vectorisation::Avx2 && !vectorisation_available(v)) v = Vectorisation::Portable;
  path_ = v;
}

void RealtimeFilter::set_input_limit(double limit) {
  if (!(limit > 0.0 && limit <= kDefaultInputLimit))
    throw InvalidParameter("input_limit", fmt::format("input_limit = {} is out of range: must be in (0, {}] (the "
                                                      "largest accepted |sample|; larger bounds could overflow the "
                                                      "state)",
                                                      limit, kDefaultInputLimit));
  input_limit_ = limit;
}

void RealtimeFilter::reset() noexcept {
  std::fill(q_.begin(), q_.end(), 0.0);
  std::fill(q_tmp_.begin(), q_tmp_.end(), 0.0);
  held_ = 0.0;
  skipped_ = 0;
  samples_ = 0;
}

std::size_t RealtimeFilter::state_size() const noexcept { return kHeader + 2 * static_cast<std::size_t>(disc_.n); }

void RealtimeFilter::save_state(std::span<double> out) const {
  if (out.size() < state_size())
    throw InvalidParameter("state", fmt::format("state buffer has {} entries: must have at least state_size() = {}",
                                                out.size(), state_size()));
  out[0] = kMagic;
  out[1] = kLayoutVersion;
  out[2] = bank_.harmonics();
  out[3] = disc_.n;  // internal coordinates in the documented order (not the kernel's lanes)
  out[4] = static_cast<double>(disc_.fingerprint >> 32);
  out[5] = static_cast<double>(disc_.fingerprint & 0xffffffffULL);
  out[6] = held_;
  out[7] = static_cast<double>(skipped_);
  out[8] = static_cast<double>(samples_);
  out[9] = disc_.n;
  const std::vector<double> q = internal_state();
  std::copy(q.begin(), q.end(), out.begin() + kHeader);
  const Eigen::VectorXd z = to_physical(bank_, disc_, q.data());
  std::copy(z.data(), z.data() + z.size(), out.begin() + kHeader + disc_.n);
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
  // Every count is checked against its range before it is converted (a double beyond the range of the integer
  // type makes the conversion undefined).
  const auto whole_in = [](double x, double lo, double hi) { return x >= lo && x <= hi && x == std::floor(x); };
  const double n_osc = in[2], ni = in[3], np = in[9];
  const double entries = static_cast<double>(in.size());
  if (!whole_in(n_osc, 1.0, kMaxHarmonicsBlock) || np != 2 * n_osc + 1 || !whole_in(ni, 0.0, entries) ||
      entries != static_cast<double>(kHeader) + ni + np)
    bad(fmt::format("inconsistent sizes (N = {}, internal {}, physical {}, total {}; N must be 1 … {})", n_osc, ni,
                    np, in.size(), kMaxHarmonicsBlock));
  constexpr double kTwo32 = 4294967296.0, kTwo64 = 18446744073709551616.0;
  if (!whole_in(in[4], 0.0, kTwo32 - 1) || !whole_in(in[5], 0.0, kTwo32 - 1))
    bad("configuration fingerprint: each half must be a whole number in 0 … 2^32 - 1");
  for (int i = 7; i <= 8; ++i)
    if (!(whole_in(in[i], 0.0, kTwo64) && in[i] < kTwo64))
      bad(fmt::format("counter [{}] = {:g}: must be a whole number in 0 … 2^64 - 1", i, in[i]));
  if (in[7] > in[8]) bad(fmt::format("{:g} skipped samples of {:g} processed", in[7], in[8]));
  // The held output and the coordinates: a state reached from samples within the input limit stays below
  // kMaxStateMagnitude (the overflow argument in realtime_filter.hpp); a larger one was not saved by a filter.
  for (std::size_t i = 6; i < in.size(); i = i == 6 ? kHeader : i + 1)
    if (std::abs(in[i]) > kMaxStateMagnitude)
      bad(fmt::format("entry [{}] = {:g}: the held output and the coordinates must be within ±{:g}", i, in[i],
                      kMaxStateMagnitude));
  const std::uint64_t fp = (static_cast<std::uint64_t>(in[4]) << 32) | static_cast<std::uint64_t>(in[5]);
  std::vector<double> qv;
  if (fp == disc_.fingerprint && ni == disc_.n) {
    qv = pack(disc_, in.data() + kHeader);  // bit for bit
  } else {
    const auto off = static_cast<std::ptrdiff_t>(kHeader + static_cast<std::size_t>(ni));
    Eigen::VectorXd z(static_cast<Eigen::Index>(np));
    for (Eigen::Index i = 0; i < z.size(); ++i) z(i) = in[off + i];
    const Eigen::VectorXd q = to_internal(bank_, disc_, map_state(z, bank_.harmonics()));
    qv = pack(disc_, q.data());
    for (double x : qv)
      if (!(std::abs(x) <= kMaxStateMagnitude))
        bad(fmt::format("its physical state maps to internal coordinates beyond ±{:g} in this configuration",
                        kMaxStateMagnitude));
  }
  q_.swap(qv);
  held_ = in[6];
  skipped_ = static_cast<std::uint64_t>(in[7]);
  samples_ = static_cast<std::uint64_t>(in[8]);
}

ModalCoefficients RealtimeFilter::modal_coefficients() const {
  const Discretisation& d = disc_;
  if (d.kind != Kind::Modal)
    throw InvalidParameter("form", "modal coefficients exist only for the zero-order-hold form in modal coordinates "
                                   "(uses_modal_form() is false: block form or dense fallback)");
  ModalCoefficients mc;
  mc.sample_rate = sample_rate_;
  for (int j = 0; j < d.pairs; ++j) {
    const auto i = static_cast<std::size_t>(2 * j);
    mc.pairs.push_back({d.c[i], d.s[i], d.c[i + 1], d.s[i + 1], d.g[i], d.g[i + 1], d.w[i], d.w[i + 1], d.e[i],
                        d.e[i + 1], d.modes[static_cast<std::size_t>(j)].lambda,
                        d.modes[static_cast<std::size_t>(j)].rejected});
  }
  for (int j = 0; j < d.reals; ++j) {
    const auto i = static_cast<std::size_t>(2 * d.pairs + j);
    mc.reals.push_back({d.r[static_cast<std::size_t>(j)], d.gr[static_cast<std::size_t>(j)], d.w[i], d.e[i],
                        d.modes[static_cast<std::size_t>(d.pairs + j)].lambda.real()});
  }
  return mc;
}

std::vector<double> RealtimeFilter::modal_state() const {
  if (disc_.kind != Kind::Modal)
    throw InvalidParameter("form", "the modal state exists only for the zero-order-hold form in modal coordinates");
  return internal_state();
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
  Eigen::MatrixXd phi(d.n, d.n);  // Φ = V T V⁻¹, one column at a time (V not stored)
  for (int i = 0; i < d.n; ++i) {
    const Eigen::VectorXd q = t * to_internal(bank_, d, Eigen::VectorXd::Unit(d.n, i));
    phi.col(i) = to_physical(bank_, d, q.data());
  }
  return phi;
}

Eigen::VectorXd RealtimeFilter::input_vector() const {
  const Discretisation& d = disc_;
  if (d.kind == Kind::Dense) return Eigen::Map<const Eigen::VectorXd>(d.gamma.data(), d.n);
  Eigen::VectorXd g(d.n);
  if (d.kind == Kind::Block) g(0) = d.g0;
  for (int j = 0; j < 2 * d.pairs; ++j) g(d.offset + j) = d.g[j];
  for (int j = 0; j < d.reals; ++j) g(2 * d.pairs + j) = d.gr[j];
  return to_physical(bank_, d, g.data());
}

Eigen::RowVectorXd RealtimeFilter::output_vector() const {
  const Discretisation& d = disc_;
  if (d.kind == Kind::Dense) return Eigen::Map<const Eigen::RowVectorXd>(d.out.data(), d.n);
  if (d.kind == Kind::Block) {
    Eigen::RowVectorXd w = Eigen::RowVectorXd::Zero(d.n);
    for (int j = 0; j < d.pairs; ++j) w(1 + 2 * j) = d.kw[2 * j + 1];
    return w;
  }
  const Eigen::Map<const Eigen::RowVectorXd> w(d.w.data(), d.n);
  Eigen::RowVectorXd c(d.n);  // C = w V⁻¹
  for (int i = 0; i < d.n; ++i) c(i) = w.dot(to_internal(bank_, d, Eigen::VectorXd::Unit(d.n, i)));
  return c;
}

}  // namespace afmkit::control
