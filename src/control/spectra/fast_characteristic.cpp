#include "fast_characteristic.hpp"

#include <cmath>
#include <numbers>

namespace afmkit::control::spectra_detail {

using cplx = std::complex<double>;

namespace {
// 1/z without the overflow guards of the library complex division (|z| is moderate here)
inline cplx reciprocal(cplx z) {
  const double n = z.real() * z.real() + z.imag() * z.imag();
  return {z.real() / n, -z.imag() / n};
}
}  // namespace

FastCharacteristic::FastCharacteristic(const LoopSpec& loop) : omega_(loop.rotation_frequency()) {
  const auto set_bank = [this](const Bank& b) {
    if (const auto* o = std::get_if<OscillatorBank>(&b)) {
      bank_ = detail::split_bank(*o);
    } else {
      const auto& i = std::get<InfiniteBank>(b);
      infinite_ = true;
      alpha_ = i.alpha;
      beta_ = i.beta;
    }
  };
  const double gain = loop.gain();
  first_order_ = loop.plant_kind == PlantKind::FirstOrder;
  rate_ = loop.plant_rate;
  rho_ = gain / loop.plant_rate;
  delay_ = loop.delay;
  if (const auto* sp = std::get_if<SmithPredictor>(&loop.controller)) {
    smith_ = true;
    set_bank(sp->bank);
    model_first_order_ = sp->model_kind == PlantKind::FirstOrder;
    model_rate_ = sp->model_rate;
    k_over_model_ = gain / sp->model_rate;
    measurement_delay_ = sp->measurement_delay();
    correction_delay_ = sp->correction_delay();
  } else if (const auto* o = std::get_if<OscillatorBank>(&loop.controller)) {
    set_bank(Bank(*o));
  } else {
    set_bank(Bank(std::get<InfiniteBank>(loop.controller)));
  }
}

void FastCharacteristic::bank(cplx s, cplx& d, cplx& dd, cplx& n, cplx& dn, cplx& log_dq, cplx* q) const {
  if (!infinite_) {
    const cplx inv_s = reciprocal(s);
    const cplx s2 = s * s;
    const detail::BankSums kept = detail::bank_sums(bank_.kept, s), rej = detail::bank_sums(bank_.rejected, s);
    d = 1.0 + bank_.a0 * inv_s + kept.g;
    dd = -bank_.a0 * inv_s * inv_s + kept.a_inv - 2.0 * s * kept.g_inv;
    n = rej.g;
    dn = rej.a_inv - 2.0 * s * rej.g_inv;
    // Q'/Q, Q = [s] Π (1 + s²/(k²Ω²))
    log_dq = (bank_.a0 != 0.0 ? inv_s : cplx(0.0)) + 2.0 * s * (kept.inv + rej.inv);
    if (q) *q = detail::normaliser_product(bank_.inv_kw2, s2, bank_.a0 != 0.0 ? s : cplx(1.0));
    return;
  }
  // N = ∞: coth(u), u = πs/Ω, via e^{−2u} (or e^{2u}) to avoid overflow
  const double c = std::numbers::pi / omega_;
  const cplx u = c * s;
  cplx coth;
  if (u.real() >= 0.0) {
    const cplx e = std::exp(-2.0 * u);
    coth = (1.0 + e) * reciprocal(1.0 - e);
  } else {
    const cplx e = std::exp(2.0 * u);
    coth = -(1.0 + e) * reciprocal(1.0 - e);
  }
  const cplx dcoth = c * (1.0 - coth * coth);
  log_dq = c * coth;  // Q∞'/Q∞
  if (q) *q = std::sinh(u) / c;  // Q∞ = (Ω/π) sinh(πs/Ω)
  const cplx inv_s = reciprocal(s);
  const cplx lin = c * (alpha_ + beta_ * omega_ * inv_s);  // (π/Ω)(α + βΩ/s)
  const cplx dlin = -c * beta_ * omega_ * inv_s * inv_s;
  const cplx inv_w = reciprocal(s * s + omega_ * omega_);
  const cplx h1 = 2.0 * (alpha_ * s + beta_ * omega_) * inv_w;
  const cplx dh1 = (2.0 * alpha_ - 2.0 * s * h1) * inv_w;
  d = 1.0 + lin * coth - beta_ * omega_ * inv_s * inv_s - h1;
  dd = dlin * coth + lin * dcoth + 2.0 * beta_ * omega_ * inv_s * inv_s * inv_s - dh1;
  n = h1;
  dn = dh1;
}

void FastCharacteristic::evaluate(cplx s, cplx& f, cplx& df) const {
  cplx lq;
  evaluate(s, f, df, lq, nullptr);
}

void FastCharacteristic::entire(cplx s, cplx& delta, cplx& ddelta) const {
  cplx f, df, lq, q;
  evaluate(s, f, df, lq, &q);
  delta = q * f;
  ddelta = q * (lq * f + df);
}

void FastCharacteristic::crossing_parts(double nu, cplx& x, cplx& y) const {
  const cplx s(0.0, nu);
  cplx d, dd, n, dn, lq;
  bank(s, d, dd, n, dn, lq, nullptr);
  const cplx m = first_order_ ? 1.0 + s / rate_ : cplx(1.0);
  if (!smith_) {
    x = m * d;
    y = rho_ * n;
    return;
  }
  const cplx mh = model_first_order_ ? 1.0 + s / model_rate_ : cplx(1.0);
  x = m * mh * d + k_over_model_ * m * (1.0 - std::exp(-s * correction_delay_)) * n;
  y = rho_ * mh * std::exp(-s * measurement_delay_) * n;
}

void FastCharacteristic::evaluate(cplx s, cplx& f, cplx& df, cplx& log_dq, cplx* q) const {
  cplx d, dd, n, dn;
  bank(s, d, dd, n, dn, log_dq, q);
  const cplx m = first_order_ ? 1.0 + s / rate_ : cplx(1.0);
  const double dm = first_order_ ? 1.0 / rate_ : 0.0;
  cplx cd, dcd, cn, dcn;
  if (!smith_) {
    const cplx e = delay_ > 0.0 ? std::exp(-s * delay_) : cplx(1.0);
    cd = m;
    dcd = dm;
    cn = rho_ * e;
    dcn = -delay_ * cn;
  } else {
    const cplx mh = model_first_order_ ? 1.0 + s / model_rate_ : cplx(1.0);
    const double dmh = model_first_order_ ? 1.0 / model_rate_ : 0.0;
    const double tm = measurement_delay_ + delay_, tc = correction_delay_;
    const cplx ec = tc > 0.0 ? std::exp(-s * tc) : cplx(1.0);
    const cplx em = tm > 0.0 ? std::exp(-s * tm) : cplx(1.0);
    cd = m * mh;
    dcd = dm * mh + m * dmh;
    cn = k_over_model_ * m * (1.0 - ec) + rho_ * mh * em;
    dcn = k_over_model_ * (dm * (1.0 - ec) + m * tc * ec) + rho_ * (dmh * em - tm * mh * em);
  }
  f = cd * d + cn * n;
  df = dcd * d + cd * dd + dcn * n + cn * dn;
}

cplx FastCharacteristic::newton_step(cplx s) const {
  cplx f, df, lq;
  evaluate(s, f, df, lq, nullptr);
  return 1.0 / (lq + df / f);
}

}  // namespace afmkit::control::spectra_detail
