// D-subdivision boundaries (stability_chart.hpp).
#include <algorithm>
#include <cmath>

#include "afmkit/control/spectrum.hpp"
#include "afmkit/control/stability_chart.hpp"
#include "afmkit/core/validate.hpp"
#include "fast_characteristic.hpp"
#include "spectra_detail.hpp"

namespace afmkit::control {

namespace {
using cplx = std::complex<double>;

// Δ(s; x, y) = e0 + x ex + y ey from three members of the family (Δ is affine in the couplings). The members share
// the normaliser Q (same N, a0 ≠ 0), so the fast O(N) evaluation keeps them on one scale; the scaled evaluation of
// loop.hpp where the fast one is not finite (exactly at s = ±ikΩ).
class AffineCharacteristic {
 public:
  explicit AffineCharacteristic(const LoopFamily& f)
      : w_(f.rotation_frequency),
        p0_(f.at(w_, 0.0)),
        p1_(f.at(2.0 * w_, 0.0)),
        p2_(f.at(w_, w_)),
        f0_(p0_),
        f1_(p1_),
        f2_(p2_) {}
  void parts(cplx s, cplx& e0, cplx& ex, cplx& ey) const {
    cplx v0, v1, v2, d;
    f0_.entire(s, v0, d);
    f1_.entire(s, v1, d);
    f2_.entire(s, v2, d);
    if (!(finite(v0) && finite(v1) && finite(v2))) {
      const auto a = characteristic_scaled(p0_, s), b = characteristic_scaled(p1_, s), c = characteristic_scaled(p2_, s);
      v0 = a.value;
      v1 = b.value * std::exp(b.log_scale - a.log_scale);
      v2 = c.value * std::exp(c.log_scale - a.log_scale);
    }
    ex = (v1 - v0) / w_;
    ey = (v2 - v0) / w_;
    e0 = v0 - w_ * ex;
  }

 private:
  static bool finite(cplx z) { return std::isfinite(z.real()) && std::isfinite(z.imag()); }
  double w_;
  LoopSpec p0_, p1_, p2_;
  spectra_detail::FastCharacteristic f0_, f1_, f2_;
};
}  // namespace

std::vector<BoundaryCurve> stability_boundaries(const LoopFamily& family, double x_min, double x_max, double y_min,
                                                double y_max, double max_frequency) {
  spectra_detail::validate_window(x_min, x_max, y_min, y_max);
  const double omega = family.rotation_frequency;
  if (std::isnan(max_frequency)) {
    max_frequency = 0.0;
    for (double x : {x_min, x_max, 0.5 * (x_min + x_max)})
      for (double y : {y_min, y_max, 0.5 * (y_min + y_max)}) {
        if (family.kind != LoopFamily::Kind::SingleOscillator && x == 0.0) continue;
        const RootBounds rb = root_bounds(family.at(x, y), 0.0);
        max_frequency = std::max(max_frequency, rb.proven ? rb.imag_max : (family.harmonics + 20) * omega);
      }
    // cap: 200 Ω, or above the top oscillator of a larger bank (its crossings are near kΩ, k ≤ N)
    const double cap = family.kind == LoopFamily::Kind::Bank ? std::max(200.0, family.harmonics + 20.0) : 200.0;
    max_frequency = std::min(std::max(max_frequency, 4.0 * omega), cap * omega);
  } else {
    validate::positive("max_frequency", max_frequency);
  }
  const AffineCharacteristic ac(family);
  const double lx = x_max - x_min, ly = y_max - y_min;
  const auto inside = [&](double x, double y) {
    return x >= x_min - 0.02 * lx && x <= x_max + 0.02 * lx && y >= y_min - 0.02 * ly && y <= y_max + 0.02 * ly;
  };
  std::vector<BoundaryCurve> curves;

  // ν = 0: the real line Re e0 + x Re ex + y Re ey = 0, clipped to the window
  {
    cplx e0, ex, ey;
    ac.parts(0.0, e0, ex, ey);
    const double c0 = e0.real(), cx = ex.real(), cy = ey.real();
    BoundaryCurve line;
    if (std::abs(cy) >= std::abs(cx) && cy != 0.0) {
      for (double x : {x_min, x_max}) line.push_back({0.0, x, -(c0 + cx * x) / cy});
    } else if (cx != 0.0) {
      for (double y : {y_min, y_max}) line.push_back({0.0, -(c0 + cy * y) / cx, y});
    }
    // clip the segment to the window (Liang–Barsky)
    if (line.size() == 2) {
      double t0 = 0.0, t1 = 1.0;
      const double dx = line[1].x - line[0].x, dy = line[1].y - line[0].y;
      const double p[4] = {-dx, dx, -dy, dy};
      const double q[4] = {line[0].x - x_min, x_max - line[0].x, line[0].y - y_min, y_max - line[0].y};
      bool visible = true;
      for (int i = 0; i < 4 && visible; ++i) {
        if (p[i] == 0.0) {
          if (q[i] < 0.0) visible = false;
        } else {
          const double t = q[i] / p[i];
          if (p[i] < 0.0) t0 = std::max(t0, t);
          else t1 = std::min(t1, t);
        }
      }
      if (visible && t0 < t1) {
        const BoundaryPoint a{0.0, line[0].x + t0 * dx, line[0].y + t0 * dy};
        const BoundaryPoint b{0.0, line[0].x + t1 * dx, line[0].y + t1 * dy};
        curves.push_back({a, b});
      }
    }
  }

  // ν > 0: solve [Re ex, Re ey; Im ex, Im ey] (x, y) = −(Re e0, Im e0)
  const auto point = [&](double nu, double& x, double& y) {
    cplx e0, ex, ey;
    ac.parts(cplx(0.0, nu), e0, ex, ey);
    const double det = ex.real() * ey.imag() - ey.real() * ex.imag();
    const double scale = std::abs(ex) * std::abs(ey);
    if (!(std::abs(det) > 1e-13 * scale)) return false;
    x = (-e0.real() * ey.imag() + ey.real() * e0.imag()) / det;
    y = (-ex.real() * e0.imag() + ex.imag() * e0.real()) / det;
    return std::isfinite(x) && std::isfinite(y);
  };
  const double h_min = 1e-9 * omega, h_max = 0.02 * omega;
  double nu = 1e-4 * omega, h = 1e-3 * omega;
  double x = 0, y = 0;
  bool have = point(nu, x, y);
  BoundaryCurve cur;
  if (have && inside(x, y)) cur.push_back({nu, x, y});
  while (nu < max_frequency) {
    const double nn = std::min(nu + h, max_frequency);
    double xn = 0, yn = 0;
    const bool ok = point(nn, xn, yn);
    const bool in_now = have && inside(x, y), in_next = ok && inside(xn, yn);
    if (ok && have && (in_now || in_next)) {
      const double d = std::hypot((xn - x) / lx, (yn - y) / ly);
      if (d > 0.01 && h > h_min) {
        h *= 0.5;
        continue;
      }
      if (d > 0.01) {  // jump (singular system): split the curve
        if (cur.size() > 1) curves.push_back(cur);
        cur.clear();
      } else if (d < 0.002) {
        h = std::min(h_max, 1.5 * h);
      }
    } else {
      h = std::min(h_max, 1.5 * h);
    }
    if (in_next) {
      if (cur.empty() && have && ok) cur.push_back({nu, x, y});  // entering: keep the outside point for clipping
      cur.push_back({nn, xn, yn});
    } else if (!cur.empty()) {
      if (ok) cur.push_back({nn, xn, yn});  // leaving
      if (cur.size() > 1) curves.push_back(cur);
      cur.clear();
    }
    nu = nn;
    x = xn;
    y = yn;
    have = ok;
  }
  if (cur.size() > 1) curves.push_back(cur);
  return curves;
}

}  // namespace afmkit::control
