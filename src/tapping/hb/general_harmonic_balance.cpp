// Harmonic balance for any force law: continuation of the first-harmonic curve F(g, B) = 0 (see the header).
#include "general_harmonic_balance.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include <boost/math/tools/toms748_solve.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::tapping::detail {

namespace {

using std::numbers::pi;  // (a using-declaration: repeatable in a unity build)
constexpr double u_far = 14.5;         // q_c ≈ cosh(14.5) ≈ 1e6: far end of the free branch (u = −u_far)
constexpr double u_deep = 9.9;         // q_c ≈ −cosh(9.9) ≈ −1e4: deepest permanent contact traced (u = π + u_deep)
constexpr double f_tolerance = 1e-13;  // |F| accepted as a root (F is relative to Γ)
constexpr double step_max = 0.5;       // continuation step bounds (in (u, v))
constexpr double step_min = 1e-8;   // (u is resolved to ~1e-8 next to a break: B u²/2 vs rounding of g)
constexpr double step_first = 0.05;
constexpr std::size_t max_nodes = 20000;
constexpr double b_min_trace = 1e-9;   // B/B_free below which a component ends
constexpr double b_min_grid = 1e-7;

// q_c − 1 and q_c as functions of u (see the header), accurate near the breaks u = 0, π.
double qc_minus_one(double u) {
  if (u < 0.0) {
    const double s = std::sinh(0.5 * u);
    return 2.0 * s * s;
  }
  if (u <= pi) {
    const double s = std::sin(0.5 * u);
    return -2.0 * s * s;
  }
  return -1.0 - std::cosh(u - pi);
}
double qc_of(double u) { return u > pi ? -std::cosh(u - pi) : (u < 0.0 ? std::cosh(u) : std::cos(u)); }
double dqc_du(double u) { return u < 0.0 ? std::sinh(u) : (u <= pi ? -std::sin(u) : -std::sinh(u - pi)); }

// u from the mean gap, the amplitude and the contact edge.
double u_of(double g, double b, double dc) {
  const double m = ((g - dc) - b) / b;  // q_c − 1
  if (m >= 0.0) return -2.0 * std::asinh(std::sqrt(0.5 * m));
  const double qc = 1.0 + m;
  if (qc > -1.0) {
    if (m > -1.0) return 2.0 * std::asin(std::sqrt(-0.5 * m));
    return pi - 2.0 * std::asin(std::min(1.0, std::sqrt(0.5 * ((g - dc) + b) / b)));
  }
  return pi + std::acosh(-qc);
}

// Smooth regions of F in u: 0 (u < 0), 1 ([0, π]), 2 (u > π).
int region_of(double u) { return u < 0.0 ? 0 : (u <= pi ? 1 : 2); }
// Region a node continues into (a node on a break belongs to the side its tangent points to).
int heading_region(double u, double tu) {
  if (u == 0.0) return tu >= 0.0 ? 1 : 0;
  if (u == pi) return tu > 0.0 ? 2 : 1;
  return region_of(u);
}
// Direction of one-sided u differences inside a region (away from its breaks).
int fd_side(int region, double u) {
  if (region == 0) return -1;
  if (region == 2) return +1;
  return u < 0.5 * pi ? +1 : -1;
}
double break_distance(int region, double u) {
  if (region == 0) return -u;
  if (region == 2) return u - pi;
  return std::min(u, pi - u);
}

// First break strictly between u0 and u1 (nearest to u0).
bool crosses_break(double u0, double u1, double& at) {
  bool found = false;
  for (const double b : {0.0, pi}) {
    if ((u0 < b && u1 > b) || (u0 > b && u1 < b)) {
      if (!found || std::abs(b - u0) < std::abs(at - u0)) at = b;
      found = true;
    }
  }
  return found;
}

struct Hermite {
  double u, v, du, dv;  // position and d/dσ
};
// Cubic Hermite between nodes a, b (tangents scaled by the chord length).
template <class N>
Hermite hermite(const N& a, const N& b, double s) {
  const double lu = b.e.u - a.e.u, lv = b.e.v - a.e.v;
  const double len = std::hypot(lu, lv);
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  const double d00 = 6 * s2 - 6 * s, d10 = 3 * s2 - 4 * s + 1, d01 = -6 * s2 + 6 * s, d11 = 3 * s2 - 2 * s;
  return {h00 * a.e.u + h10 * len * a.tu + h01 * b.e.u + h11 * len * b.tu,
          h00 * a.e.v + h10 * len * a.tv + h01 * b.e.v + h11 * len * b.tv,
          d00 * a.e.u + d10 * len * a.tu + d01 * b.e.u + d11 * len * b.tu,
          d00 * a.e.v + d10 * len * a.tv + d01 * b.e.v + d11 * len * b.tv};
}

// Secant iteration for a root of f(λ) from λ = 0 with value f0 and a slope estimate; |λ| ≤ limit. On success
// `slope` holds the last secant slope (≈ f' at the root) and f was last called at the root.
// `resolution`: a step below it means the iteration has reached the rounding noise of F (accepted when
// |f| ≤ 1e-9, e.g. deep permanent contact where F is a small difference of large integrals).
template <class F>
bool secant(F f, double f0, double& slope, double limit, double& root, int& iterations, double resolution = 1e-15) {
  iterations = 0;
  double x0 = 0.0, y0 = f0;
  if (std::abs(y0) <= f_tolerance) {
    root = 0.0;
    return true;
  }
  if (!(std::isfinite(slope) && slope != 0.0)) return false;
  double x1 = -y0 / slope;
  for (int it = 0; it < 12; ++it) {
    if (!(std::abs(x1) <= limit)) return false;
    const double y1 = f(x1);
    ++iterations;
    if (!std::isfinite(y1)) return false;
    const double s = (y1 - y0) / (x1 - x0);
    if (std::isfinite(s) && s != 0.0) slope = s;
    if (std::abs(y1) <= f_tolerance) {
      root = x1;
      return true;
    }
    if (!(std::isfinite(s) && s != 0.0)) return false;
    const double x2 = x1 - y1 / s;
    if (std::abs(x2 - x1) <= resolution) {
      root = x1;  // step at rounding level: accept if the residual is small
      return std::abs(y1) <= 1e-9;
    }
    x0 = x1;
    y0 = y1;
    x1 = x2;
  }
  return false;
}

// (tu, tv) scaled to unit length (left as is when zero).
void normalise(double& tu, double& tv) {
  const double n = std::hypot(tu, tv);
  if (n > 0.0) {
    tu /= n;
    tv /= n;
  }
}

// Tangent at x2 from three consecutive points (quadratic through them, non-uniform spacing), normalised.
void three_point_tangent(double u0, double v0, double u1, double v1, double u2, double v2, double& tu, double& tv) {
  const double s1 = std::hypot(u1 - u0, v1 - v0), s2 = std::hypot(u2 - u1, v2 - v1);
  if (!(s1 > 0.0 && s2 > 0.0)) {
    tu = u2 - u1;
    tv = v2 - v1;
  } else {
    const double a = s2 / (s1 * (s1 + s2)), b = -(s1 + s2) / (s1 * s2), c = (s1 + 2 * s2) / (s2 * (s1 + s2));
    tu = a * u0 + b * u1 + c * u2;
    tv = a * v0 + b * v1 + c * v2;
  }
  normalise(tu, tv);
}
// Central tangent at x1 from its two neighbours (quadratic through the three points), normalised.
void central_tangent(double u0, double v0, double u1, double v1, double u2, double v2, double& tu, double& tv) {
  const double s1 = std::hypot(u1 - u0, v1 - v0), s2 = std::hypot(u2 - u1, v2 - v1);
  if (!(s1 > 0.0 && s2 > 0.0)) return;
  const double a = -s2 / (s1 * (s1 + s2)), b = (s2 - s1) / (s1 * s2), c = s1 / (s2 * (s1 + s2));
  tu = a * u0 + b * u1 + c * u2;
  tv = a * v0 + b * v1 + c * v2;
  normalise(tu, tv);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// Evaluation

double GeneralHarmonicBalance::gap_of(double u, double b) const {
  if (u <= pi) return contact_edge_ + b + b * qc_minus_one(u);
  return contact_edge_ + b * qc_of(u);
}

void GeneralHarmonicBalance::fill(Eval& e) const {
  e.ok = false;
  if (!(std::isfinite(e.g) && e.b > 0.0 && std::isfinite(e.b))) return;
  const DescribingFunctions d = df_.at_gap(e.g, e.b);
  const std::complex<double> z = e.b * (inverse_ + d.first_harmonic);
  e.f = (std::abs(z) - gamma_) / gamma_;
  e.offset = -static_gain_ * d.mean;
  e.separation = e.g - e.offset;
  e.phase = std::arg(z);
  e.ok = std::isfinite(e.f) && std::isfinite(e.separation);
}

GeneralHarmonicBalance::Eval GeneralHarmonicBalance::evaluate(double u, double v) const {
  Eval e;
  e.u = u;
  e.v = v;
  e.b = b_ref_ * std::exp(v);
  e.g = gap_of(u, e.b);
  fill(e);
  return e;
}

GeneralHarmonicBalance::Eval GeneralHarmonicBalance::evaluate_gb(double g, double b) const {
  Eval e;
  e.g = g;
  e.b = b;
  e.u = u_of(g, b, contact_edge_);
  e.v = std::log(b / b_ref_);
  fill(e);
  return e;
}

double GeneralHarmonicBalance::ray_slope(const Eval& e) const {
  const double q = e.g / e.b;
  const double h = 1e-6;
  const double bp = e.b * std::exp(h), bm = e.b * std::exp(-h);
  const Eval p = evaluate_gb(q * bp, bp), m = evaluate_gb(q * bm, bm);
  return (p.f - m.f) / (2.0 * h);
}

HbPoint GeneralHarmonicBalance::to_point(const Eval& e, double slope) const {
  HbBranch branch = HbBranch::Minus;
  if (slope > 0.0) branch = e.u <= 0.0 ? HbBranch::Free : HbBranch::Plus;
  return {e.g / e.b, e.separation, e.b, e.offset, e.phase, branch};
}

// ---------------------------------------------------------------------------------------------------------------
// Construction

class GeneralHbBuilder {
 public:
  using Eval = GeneralHarmonicBalance::Eval;
  using Node = GeneralHarmonicBalance::Node;
  enum class End { Free, Deep, Small, Large, Loop, Budget, Failed };

  GeneralHbBuilder(GeneralHarmonicBalance& hb, const Cancellation& cancellation)
      : hb_(hb), cancellation_(cancellation) {}

  Eval eval(double u, double v) {
    if ((++count_ & 63) == 0) cancellation_.check();
    return hb_.evaluate(u, v);
  }

  // ∇F and ∇l (l in units of B_free) by forward differences (one-sided in u, into `region`).
  struct Gradient {
    double fu, fv, lu, lv;
    bool ok;
  };
  Gradient gradient(const Eval& e, int region) {
    // (u steps much below 1e-6 are not resolved next to a break: the penetration B(1 − q_c) ≈ Bu²/2 rounds away)
    const double hu = fd_side(region, e.u) * 1e-6;
    const double hv = 1e-7;
    const Eval pu = eval(e.u + hu, e.v), pv = eval(e.u, e.v + hv);
    const double s = 1.0 / hb_.b_ref_;
    return {(pu.f - e.f) / hu, (pv.f - e.f) / hv, (pu.separation - e.separation) * s / hu,
            (pv.separation - e.separation) * s / hv, pu.ok && pv.ok};
  }
  // Same to 4th order (central where the stencil stays in the region, else one-sided 5-point).
  Gradient gradient4(const Eval& e, int region) {
    const double dist = break_distance(region, e.u);
    const double hu = 1e-3 * std::clamp(dist, 1e-3, 1.0);
    const double hv = 1e-3;
    const double s = 1.0 / hb_.b_ref_;
    auto d4 = [&](double du, double dv, bool central, int side, double& df, double& dl) {
      const double h = du != 0.0 ? du : dv;
      if (central) {
        const Eval m2 = eval(e.u - 2 * du, e.v - 2 * dv), m1 = eval(e.u - du, e.v - dv);
        const Eval p1 = eval(e.u + du, e.v + dv), p2 = eval(e.u + 2 * du, e.v + 2 * dv);
        df = (m2.f - 8 * m1.f + 8 * p1.f - p2.f) / (12 * h);
        dl = (m2.separation - 8 * m1.separation + 8 * p1.separation - p2.separation) * s / (12 * h);
        return m2.ok && m1.ok && p1.ok && p2.ok;
      }
      Eval p[5];
      p[0] = e;
      for (int k = 1; k < 5; ++k) p[k] = eval(e.u + side * k * du, e.v + side * k * dv);
      const double c[5] = {-25, 48, -36, 16, -3};
      df = dl = 0;
      for (int k = 0; k < 5; ++k) {
        df += c[k] * p[k].f;
        dl += c[k] * p[k].separation;
      }
      df *= side / (12 * h);
      dl *= side * s / (12 * h);
      return p[1].ok && p[2].ok && p[3].ok && p[4].ok;
    };
    Gradient g{};
    const bool a = d4(hu, 0.0, dist > 2.5 * hu, fd_side(region, e.u), g.fu, g.lu);
    const bool b = d4(0.0, hv, true, 1, g.fv, g.lv);
    g.ok = a && b;
    return g;
  }

  // A node at e from ∇F, its tangent oriented along (ru, rv).
  static Node node_from_gradient(const Eval& e, double fu, double fv, double ru, double rv) {
    Node n;
    n.e = e;
    double tu = -fv, tv = fu;
    const double norm = std::hypot(tu, tv);
    if (!(norm > 0.0) || !std::isfinite(norm)) {
      n.tu = ru;
      n.tv = rv;
      n.sn = 0.0;
      return n;
    }
    tu /= norm;
    tv /= norm;
    if (tu * ru + tv * rv < 0.0) {
      tu = -tu;
      tv = -tv;
    }
    n.tu = tu;
    n.tv = tv;
    n.sn = -tv * fu + tu * fv;  // ∇F·n
    return n;
  }

  // dl/ds along the curve at e (4th-order differences; tangent oriented along (ru, rv)).
  double fold_slope(const Eval& e, int region, double ru, double rv) {
    const Gradient g = gradient4(e, region);
    if (!g.ok) return std::numeric_limits<double>::quiet_NaN();
    const Node n = node_from_gradient(e, g.fu, g.fv, ru, rv);
    return n.tu * g.lu + n.tv * g.lv;
  }
  // dq/ds along the curve at e (forward differences).
  double q_slope(const Eval& e, int region, double ru, double rv) {
    const Gradient g = gradient(e, region);
    if (!g.ok) return std::numeric_limits<double>::quiet_NaN();
    const Node n = node_from_gradient(e, g.fu, g.fv, ru, rv);
    return dqc_du(e.u) * n.tu - hb_.contact_edge_ / e.b * n.tv;
  }

  // Root of F along (u0 + λ mu, v0 + λ mv), |λ| ≤ limit; `slope` (in: estimate of dF/dλ) ends as the last one.
  bool correct(double u0, double v0, double mu, double mv, double& slope, double limit, Eval& out, double& lambda,
               int& iterations) {
    const Eval e0 = eval(u0, v0);
    if (!e0.ok) return false;
    Eval last = e0;
    auto f = [&](double l) {
      last = eval(u0 + l * mu, v0 + l * mv);
      return last.ok ? last.f : std::numeric_limits<double>::quiet_NaN();
    };
    if (!secant(f, e0.f, slope, limit, lambda, iterations, 2e-14 * (1.0 + std::abs(u0) + std::abs(v0))))
      return false;
    out = lambda == 0.0 ? e0 : last;  // the secant's last evaluation is at its root
    return out.ok;
  }

  // Follow the curve from nodes.back() (oriented tangent, sn) until it ends. Secant continuation: tangents from the
  // last three nodes, corrector along the normal with the previous normal slope, no gradient evaluations except at
  // corners.
  End trace(std::vector<Node>& nodes, double h) {
    const Node start = nodes.front();
    double travelled = 0.0;
    std::size_t piece_start = nodes.size() - 1;  // first node of the current smooth piece
    while (true) {
      if (nodes.size() > max_nodes) return End::Budget;
      const Node n = nodes.back();
      const int region = heading_region(n.e.u, n.tu);
      bool accepted = false;
      while (!accepted) {
        if (h < step_min) return End::Failed;
        const double pu = n.e.u + h * n.tu, pv = n.e.v + h * n.tv;
        double brk;
        if (crosses_break(n.e.u, pu, brk)) {
          // Land on the break u = brk, then continue on its other side from a second node (corner).
          if (std::abs(n.tu) < 1e-14) {
            h *= 0.5;
            continue;
          }
          const double guess = n.e.v + (brk - n.e.u) / n.tu * n.tv;
          double slope = n.sn * n.tu;  // ∂F/∂v ≈ sn·n_v
          Eval e;
          double lambda;
          int it;
          if (!correct(brk, guess, 0.0, 1.0, slope, 0.5 * h, e, lambda, it)) {
            h *= 0.5;
            continue;
          }
          e.u = brk;
          const Gradient gi = gradient(e, region);
          const int far = pu > brk ? (brk == 0.0 ? 1 : 2) : (brk == 0.0 ? 0 : 1);
          const Gradient go = gradient(e, far);
          if (!gi.ok || !go.ok) {
            h *= 0.5;
            continue;
          }
          Node in = node_from_gradient(e, gi.fu, gi.fv, n.tu, n.tv);
          const double dir = pu > brk ? 1.0 : -1.0;
          Node out = node_from_gradient(e, go.fu, go.fv, dir, 0.0);
          if (std::abs(out.tu) < 1e-6) out = node_from_gradient(e, go.fu, go.fv, n.tu, n.tv);
          in.break_after = true;
          travelled += std::hypot(e.u - n.e.u, e.v - n.e.v);
          nodes.push_back(in);
          nodes.push_back(out);
          piece_start = nodes.size() - 1;
          accepted = true;
          h = std::min(h, step_first);  // the curve may turn sharply beyond a corner
          break;
        }
        const double mu = -n.tv, mv = n.tu;
        double slope = n.sn;
        Eval e;
        double lambda;
        int it;
        if (!correct(pu, pv, mu, mv, slope, 0.3 * h, e, lambda, it)) {
          h *= 0.5;
          continue;
        }
        if (region_of(e.u) != region && !(e.u == 0.0 || e.u == pi)) {
          h *= 0.5;
          continue;
        }
        // tangent at the new node from the last three nodes of this piece
        const double cu = e.u - n.e.u, cv = e.v - n.e.v;
        const double chord = std::hypot(cu, cv);
        Node m;
        m.e = e;
        if (nodes.size() - 1 > piece_start) {
          const Node& p = nodes[nodes.size() - 2];
          three_point_tangent(p.e.u, p.e.v, n.e.u, n.e.v, e.u, e.v, m.tu, m.tv);
          // normal slope at m: the secant slope along n's normal, projected on m's normal
          m.sn = it > 0 ? slope * (mu * -m.tv + mv * m.tu) : n.sn;
        } else {  // second node of a piece: its own gradient (the chord lags by half a step)
          const Gradient g = gradient(e, region);
          if (!g.ok) {
            h *= 0.5;
            continue;
          }
          m = node_from_gradient(e, g.fu, g.fv, cu, cv);
        }
        const double turn = (cu * n.tu + cv * n.tv) / chord;  // cos(angle(chord, tangent at n))
        const double turn2 = m.tu * n.tu + m.tv * n.tv;        // cos(angle between the tangents)
        // F changes sign across the curve on the same side as before (else the corrector jumped to another part)
        const bool same_side = m.sn * n.sn > 0.0 && std::abs(m.sn) < 4.0 * std::abs(n.sn) &&
                               std::abs(n.sn) < 4.0 * std::abs(m.sn);
        if ((turn < 0.995 || turn2 < 0.985 || !same_side) && h > 8 * step_min) {
          h *= 0.5;
          continue;
        }
        nodes.push_back(m);
        travelled += chord;
        accepted = true;
        if (std::abs(lambda) < 0.05 * h && turn2 > 0.996 && it <= 3) h = std::min(1.5 * h, step_max);
      }
      const Node& last = nodes.back();
      if (last.e.u <= -u_far) return End::Free;
      if (last.e.u >= pi + u_deep) return End::Deep;
      if (last.e.b <= b_min_trace * hb_.b_ref_) return End::Small;
      if (last.e.v >= hb_.v_max_) return End::Large;
      if (travelled > 4.0 * h && std::hypot(last.e.u - start.e.u, last.e.v - start.e.v) < h &&
          last.tu * start.tu + last.tv * start.tv > 0.9) {
        nodes.push_back(start);
        nodes.back().break_after = false;
        return End::Loop;
      }
    }
  }

  // A component through the curve point e (traced both ways), in one order.
  std::vector<Node> trace_both(const Eval& e) {
    const int region = region_of(e.u);
    const Gradient gr = gradient(e, region);
    if (!gr.ok) return {};
    std::vector<Node> fwd{node_from_gradient(e, gr.fu, gr.fv, 1.0, 0.0)};
    const End end = trace(fwd, step_first);
    if (end == End::Loop) return fwd;
    Node back = fwd.front();
    back.tu = -back.tu;
    back.tv = -back.tv;
    back.sn = -back.sn;
    std::vector<Node> bwd{back};
    trace(bwd, step_first);
    // reverse the backward part (without its start) in front of the forward part
    std::vector<Node> out;
    out.reserve(bwd.size() + fwd.size());
    for (std::size_t k = bwd.size(); k-- > 1;) {
      Node x = bwd[k];
      x.tu = -x.tu;
      x.tv = -x.tv;
      x.sn = -x.sn;
      x.break_after = bwd[k - 1].break_after;  // the pair (k−1, k) reversed: flag on the first of (k, k−1)
      out.push_back(x);
    }
    out.insert(out.end(), fwd.begin(), fwd.end());
    return out;
  }

  // Centred tangents at interior nodes of each smooth piece (better Hermite interpolation than the traced ones).
  static void smooth_tangents(std::vector<Node>& c) {
    for (std::size_t k = 1; k + 1 < c.size(); ++k) {
      if (c[k - 1].break_after || c[k].break_after) continue;
      double tu = c[k].tu, tv = c[k].tv;
      central_tangent(c[k - 1].e.u, c[k - 1].e.v, c[k].e.u, c[k].e.v, c[k + 1].e.u, c[k + 1].e.v, tu, tv);
      if (tu * c[k].tu + tv * c[k].tv > 0.9) {
        const double nu = -c[k].tv, nv = c[k].tu;  // re-project the normal slope
        const double sn = c[k].sn;
        c[k].tu = tu;
        c[k].tv = tv;
        c[k].sn = sn * (nu * -tv + nv * tu);
      }
    }
  }

  // The corrected curve point at parameter σ between a and b.
  bool point(const Node& a, const Node& b, double sigma, Eval& out) {
    if (sigma == 0.0) {
      out = a.e;
      return true;
    }
    if (sigma == 1.0) {
      out = b.e;
      return true;
    }
    ++count_;  // (approximately: point_on_segment evaluates 2–4 times)
    return hb_.point_on_segment(a, b, sigma, out);
  }

  // Extremum of l (fold) or q between nodes a and b of one piece: zero of dl/ds or dq/ds.
  bool refine(const Node& a, const Node& b, bool fold, Node& out, double fa, double fb, double s_lo = 0.0,
              double s_hi = 1.0) {
    const int region = heading_region(a.e.u, a.tu);
    const double cu = b.e.u - a.e.u, cv = b.e.v - a.e.v;
    auto value_at = [&](double sigma, Eval* at) {
      Eval e;
      if (!point(a, b, sigma, e)) return std::numeric_limits<double>::quiet_NaN();
      if (at != nullptr) *at = e;
      return fold ? fold_slope(e, region, cu, cv) : q_slope(e, region, cu, cv);
    };
    if (!(fa * fb < 0.0)) return false;
    std::uintmax_t iterations = 80;
    double lo, hi;
    try {
      auto f = [&](double s) {
        const double y = value_at(s, nullptr);
        if (!std::isfinite(y)) throw NumericalFailure("harmonic balance: curve point not found");
        return y;
      };
      const auto r = boost::math::tools::toms748_solve(
          f, s_lo, s_hi, fa, fb, boost::math::tools::eps_tolerance<double>(fold ? 44 : 24), iterations);
      lo = r.first;
      hi = r.second;
    } catch (const NumericalFailure&) {
      return false;
    }
    Eval e;
    if (!point(a, b, 0.5 * (lo + hi), e)) return false;
    const Gradient g = gradient(e, region);
    if (!g.ok) return false;
    out = node_from_gradient(e, g.fu, g.fv, cu, cv);
    return true;
  }

  // Insert the extrema of l (folds) and then of q along every smooth piece as nodes: detected from node values at
  // interior nodes, and from the derivatives at the ends of the first and last segment of each piece (an extremum
  // next to a corner), located by the sign change of the derivative.
  void insert_extrema(std::vector<Node>& c, bool fold) {
    auto value = [&](const Node& n) { return fold ? n.e.separation / hb_.b_ref_ : n.e.g / n.e.b; };
    auto slope_at = [&](std::size_t k) {
      const Node& n = c[k];
      // the node before a corner belongs to the piece it ends (its own heading points across the break)
      const int region = n.break_after && k > 0 ? heading_region(c[k - 1].e.u, c[k - 1].tu)
                                                : heading_region(n.e.u, n.tu);
      return fold ? fold_slope(n.e, region, n.tu, n.tv) : q_slope(n.e, region, n.tu, n.tv);
    };
    auto insert = [&](std::size_t k, double s0, double s1, double d, double lo = 0.0, double hi = 1.0) {
      Node m;  // in segment (k, k + 1)
      if (!refine(c[k], c[k + 1], fold, m, s0, s1, lo, hi)) return false;
      m.extremum = true;
      if (fold) hb_.folds_.push_back({hb_.to_point(m.e, hb_.ray_slope(m.e)), d > 0.0});
      c.insert(c.begin() + static_cast<std::ptrdiff_t>(k + 1), m);
      return true;
    };
    // segments at the ends of pieces. At a corner node itself (u = 0 or π) the derivative along (u, v) vanishes for
    // a law that is smooth there (dq_c/du = 0): its sign is taken slightly inside the segment instead.
    const double inside = 1e-3;
    auto inner_slope = [&](std::size_t k, double sigma) {
      const int region = heading_region(c[k].e.u, c[k].tu);
      Eval e;
      if (!point(c[k], c[k + 1], sigma, e)) return std::numeric_limits<double>::quiet_NaN();
      const double cu = c[k + 1].e.u - c[k].e.u, cv = c[k + 1].e.v - c[k].e.v;
      return fold ? fold_slope(e, region, cu, cv) : q_slope(e, region, cu, cv);
    };
    auto on_break = [](const Node& n) { return n.e.u == 0.0 || n.e.u == pi; };
    for (std::size_t k = 0; k + 1 < c.size(); ++k) {
      if (c[k].break_after) continue;
      const bool first = k == 0 || c[k - 1].break_after;
      const bool last = k + 2 == c.size() || c[k + 1].break_after;
      if (!first && !last) continue;
      const double lo = first && on_break(c[k]) ? inside : 0.0;
      const double hi = last && on_break(c[k + 1]) ? 1.0 - inside : 1.0;
      const double s0 = lo > 0.0 ? inner_slope(k, lo) : slope_at(k);
      const double s1 = hi < 1.0 ? inner_slope(k, hi) : slope_at(k + 1);
      if (s0 * s1 < 0.0 && insert(k, s0, s1, s0, lo, hi)) ++k;
    }
    // interior nodes
    for (std::size_t k = 1; k + 1 < c.size(); ++k) {
      if (c[k - 1].break_after || c[k].break_after) continue;
      if (c[k - 1].extremum || c[k].extremum || c[k + 1].extremum) continue;
      const double d1 = value(c[k]) - value(c[k - 1]), d2 = value(c[k + 1]) - value(c[k]);
      const double floor = 1e-12 * (std::abs(value(c[k])) + 1.0);
      if (!(d1 * d2 < 0.0) || std::abs(d1) < floor || std::abs(d2) < floor) continue;
      const double s0 = slope_at(k - 1), s1 = slope_at(k), s2 = slope_at(k + 1);
      if (s0 * s1 < 0.0 && insert(k - 1, s0, s1, d1)) {
        ++k;
      } else if (s1 * s2 < 0.0 && insert(k, s1, s2, d1)) {
        k += 2;
      }
    }
  }

  // Mark the seed-grid cells crossed by the straight segments of a component.
  void mark(const std::vector<Node>& c) {
    std::vector<double> ts;
    for (std::size_t k = 0; k + 1 < c.size(); ++k) {
      const double u0 = c[k].e.u, v0 = c[k].e.v, u1 = c[k + 1].e.u, v1 = c[k + 1].e.v;
      ts.assign({0.0, 1.0});
      auto cuts = [&](const std::vector<double>& grid, double a, double b) {
        const double lo = std::min(a, b), hi = std::max(a, b);
        for (auto it = std::upper_bound(grid.begin(), grid.end(), lo); it != grid.end() && *it < hi; ++it)
          ts.push_back((*it - a) / (b - a));
      };
      if (u1 != u0) cuts(ug_, u0, u1);
      if (v1 != v0) cuts(vg_, v0, v1);
      std::sort(ts.begin(), ts.end());
      for (std::size_t j = 0; j + 1 < ts.size(); ++j) {
        const double t = 0.5 * (ts[j] + ts[j + 1]);
        visit(u0 + t * (u1 - u0), v0 + t * (v1 - v0));
      }
    }
    if (!c.empty()) visit(c.back().e.u, c.back().e.v);
  }
  std::ptrdiff_t cell(std::ptrdiff_t i, std::ptrdiff_t j) const {
    if (i < 0 || j < 0 || i + 1 >= static_cast<std::ptrdiff_t>(ug_.size()) ||
        j + 1 >= static_cast<std::ptrdiff_t>(vg_.size()))
      return -1;
    return i * static_cast<std::ptrdiff_t>(vg_.size() - 1) + j;
  }
  void visit(double u, double v) {
    const auto i = std::upper_bound(ug_.begin(), ug_.end(), u) - ug_.begin() - 1;
    const auto j = std::upper_bound(vg_.begin(), vg_.end(), v) - vg_.begin() - 1;
    const auto c = cell(i, j);
    if (c >= 0) visited_[static_cast<std::size_t>(c)] = true;
  }
  bool visited(std::ptrdiff_t i, std::ptrdiff_t j) const {
    const auto c = cell(i, j);
    return c >= 0 && visited_[static_cast<std::size_t>(c)];
  }

  void add_component(std::vector<Node> c, bool free_start) {
    if (c.size() < 2) return;
    mark(c);
    smooth_tangents(c);
    insert_extrema(c, true);
    insert_extrema(c, false);
    hb_.components_.push_back(std::move(c));
    hb_.free_end_.push_back(free_start);
  }

  void build() {
    build_grid();
    // 1. The branch continuing the free oscillation, from q_c ≈ 1e6 towards contact.
    {
      const Eval base = eval(-u_far, 0.0);
      const Eval probe = eval(-u_far, 1e-6);
      double slope = (probe.f - base.f) / 1e-6;
      Eval e;
      double lambda;
      int it;
      if (base.ok && probe.ok && correct(-u_far, 0.0, 0.0, 1.0, slope, 2.0, e, lambda, it)) {
        const Gradient g = gradient(e, 0);
        if (g.ok) {
          std::vector<Node> c{node_from_gradient(e, g.fu, g.fv, 1.0, 0.0)};
          trace(c, step_first);
          add_component(std::move(c), true);
        }
      }
    }
    // 2. Every other component crossing an unvisited cell of the seed grid.
    const std::size_t nu = ug_.size(), nv = vg_.size();
    for (std::size_t i = 0; i < nu; ++i) {
      for (std::size_t j = 0; j < nv; ++j) {
        for (int dir = 0; dir < 2; ++dir) {
          const std::size_t i2 = i + (dir == 0 ? 1 : 0), j2 = j + (dir == 1 ? 1 : 0);
          if (i2 >= nu || j2 >= nv) continue;
          const double f1 = fg_[i * nv + j], f2 = fg_[i2 * nv + j2];
          if (!(f1 * f2 < 0.0)) continue;
          const auto ii = static_cast<std::ptrdiff_t>(i), jj = static_cast<std::ptrdiff_t>(j);
          const bool explained =
              dir == 0 ? (visited(ii, jj - 1) || visited(ii, jj)) : (visited(ii - 1, jj) || visited(ii, jj));
          if (explained) continue;
          const double ua = ug_[i], va = vg_[j], ub = ug_[i2], vb = vg_[j2];
          Eval root;
          try {
            std::uintmax_t iterations = 100;
            auto f = [&](double t) {
              const Eval e = eval(ua + t * (ub - ua), va + t * (vb - va));
              if (!e.ok) throw NumericalFailure("harmonic balance: F not finite on a seed edge");
              return e.f;
            };
            const auto r = boost::math::tools::toms748_solve(f, 0.0, 1.0, f1, f2,
                                                             boost::math::tools::eps_tolerance<double>(50), iterations);
            const double t = 0.5 * (r.first + r.second);
            root = eval(ua + t * (ub - ua), va + t * (vb - va));
          } catch (const NumericalFailure&) {
            continue;
          }
          if (!root.ok || std::abs(root.f) > 1e-9 || near_existing(root)) continue;
          add_component(trace_both(root), false);
        }
      }
    }
  }

  bool near_existing(const Eval& e) const {
    for (const auto& c : hb_.components_) {
      for (std::size_t k = 0; k + 1 < c.size(); ++k) {
        const Node& a = c[k];
        const Node& b = c[k + 1];
        const double cu = b.e.u - a.e.u, cv = b.e.v - a.e.v;
        const double len2 = cu * cu + cv * cv;
        const double t = len2 > 0 ? std::clamp(((e.u - a.e.u) * cu + (e.v - a.e.v) * cv) / len2, 0.0, 1.0) : 0.0;
        const double d = std::hypot(e.u - a.e.u - t * cu, e.v - a.e.v - t * cv);
        const double turn = std::acos(std::clamp(a.tu * b.tu + a.tv * b.tv, -1.0, 1.0));
        if (d <= 1e-7 + 0.25 * std::sqrt(len2) * turn) return true;
      }
    }
    return false;
  }

  // Seed grid: u log-spaced towards the breaks, B log-spaced (3 per decade).
  void build_grid() {
    ug_.clear();
    for (int k = 0; k < 8; ++k) ug_.push_back(-u_far * std::pow(1e-3 / u_far, k / 7.0));
    ug_.push_back(0.0);
    for (int k = 0; k < 9; ++k) ug_.push_back(1e-4 * std::pow(0.3 / 1e-4, k / 8.0));
    for (int k = 1; k <= 12; ++k) ug_.push_back(0.3 + (pi - 0.3) * k / 12.0);
    for (int k = 1; k <= 8; ++k) ug_.push_back(pi + std::acosh(std::pow(10.0, k / 2.0)));
    std::sort(ug_.begin(), ug_.end());
    vg_.clear();
    const double lo = std::log(b_min_grid), hi = hb_.v_max_;
    const int nv = static_cast<int>(std::ceil((hi - lo) / std::log(10.0) * 3.0));
    for (int k = 0; k <= nv; ++k) vg_.push_back(lo + (hi - lo) * k / nv);
    fg_.assign(ug_.size() * vg_.size(), std::numeric_limits<double>::quiet_NaN());
    for (std::size_t i = 0; i < ug_.size(); ++i)
      for (std::size_t j = 0; j < vg_.size(); ++j) {
        const Eval e = eval(ug_[i], vg_[j]);
        if (e.ok) fg_[i * vg_.size() + j] = e.f;
      }
    visited_.assign((ug_.size() - 1) * (vg_.size() - 1), false);
  }

  long count() const { return count_; }

 private:
  GeneralHarmonicBalance& hb_;
  const Cancellation& cancellation_;
  long count_ = 0;
  std::vector<double> ug_, vg_, fg_;
  std::vector<bool> visited_;
};

// ---------------------------------------------------------------------------------------------------------------

GeneralHarmonicBalance::GeneralHarmonicBalance(const TappingModel& model, const Cancellation& cancellation)
    : df_(model.law, model.drive.frequency),
      static_gain_(model.cantilever.static_gain()),
      gamma_(model.drive.amplitude) {
  const double wn = model.cantilever.natural_frequency;
  const double w = model.drive.frequency;
  inverse_ = {wn * wn - w * w, 2.0 * model.cantilever.damping_ratio() * wn * w};
  b_ref_ = gamma_ / std::abs(inverse_);
  const std::vector<double>& gaps = model.law.switching_gaps();
  contact_edge_ = gaps.empty() ? 0.0 : *std::max_element(gaps.begin(), gaps.end());
  // B ≤ Γ/Im L(iω)⁻¹ for a dissipative law (Im N1 ≥ 0); margin for laws that gain energy.
  v_max_ = std::log(std::max(2.0, 1.5 * std::abs(inverse_) / inverse_.imag()));
  v_min_ = std::log(b_min_trace);
  GeneralHbBuilder builder(*this, cancellation);
  builder.build();
  construction_evaluations_ = builder.count();
  std::sort(folds_.begin(), folds_.end(), [](const HbFold& a, const HbFold& b) { return a.point.q < b.point.q; });
}

int GeneralHarmonicBalance::nodes() const {
  int n = 0;
  for (const auto& c : components_) n += static_cast<int>(c.size());
  return n;
}

// ---------------------------------------------------------------------------------------------------------------
// Queries

bool GeneralHarmonicBalance::point_on_segment(const Node& a, const Node& b, double sigma, Eval& out) const {
  const Hermite h = hermite(a, b, sigma);
  const double cu = b.e.u - a.e.u, cv = b.e.v - a.e.v;
  const double len = std::hypot(cu, cv);
  if (!(len > 0.0)) {
    out = a.e;
    return true;
  }
  const double mu = -cv / len, mv = cu / len;
  // ∇F ≈ sn·n at the nodes (n = (−tv, tu)): the slope along the chord normal
  double slope = (1 - sigma) * a.sn * (-a.tv * mu + a.tu * mv) + sigma * b.sn * (-b.tv * mu + b.tu * mv);
  Eval last;
  auto f = [&](double l) {
    last = evaluate(h.u + l * mu, h.v + l * mv);
    return last.ok ? last.f : std::numeric_limits<double>::quiet_NaN();
  };
  const Eval e0 = evaluate(h.u, h.v);
  if (!e0.ok) return false;
  double lambda;
  int it;
  const double limit = 0.5 * len + 1e-12;
  if (secant(f, e0.f, slope, limit, lambda, it, 2e-14 * (1.0 + std::abs(h.u) + std::abs(h.v)))) {
    out = lambda == 0.0 ? e0 : last;
    return out.ok;
  }
  // fallback: bracket the root on the normal line and refine
  const int n = 8;
  double prev_l = -limit;
  double prev_f = f(prev_l);
  double best = std::numeric_limits<double>::infinity();
  bool found = false;
  for (int k = 1; k <= 2 * n; ++k) {
    const double x = -limit + limit * k / n;
    const double y = f(x);
    if (std::isfinite(prev_f) && std::isfinite(y) && prev_f * y <= 0.0) {
      std::uintmax_t iterations = 100;
      const auto r = boost::math::tools::toms748_solve(f, prev_l, x, prev_f, y,
                                                       boost::math::tools::eps_tolerance<double>(50), iterations);
      const double root = 0.5 * (r.first + r.second);
      if (std::abs(root) < best) {
        best = std::abs(root);
        out = evaluate(h.u + root * mu, h.v + root * mv);
        found = out.ok;
      }
    }
    prev_l = x;
    prev_f = y;
  }
  return found;
}

// Root of F on the ray (A + l)/B = q, starting from the curve between a and b.
bool GeneralHarmonicBalance::solve_on_ray(double q, const Node& a, const Node& b, Eval& out, double& slope) const {
  // σ where the Hermite curve meets the ray (arithmetic only)
  auto q_at = [&](const Hermite& h) { return contact_edge_ / (b_ref_ * std::exp(h.v)) + qc_of(h.u); };
  const double qa = a.e.g / a.e.b, qb = b.e.g / b.e.b;
  double lo = 0.0, hi = 1.0;
  const bool increasing = qb > qa;
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    const double qm = q_at(hermite(a, b, mid));
    if ((qm < q) == increasing) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  const double sigma = 0.5 * (lo + hi);
  const Hermite h = hermite(a, b, sigma);
  const double w0 = h.v;
  // slope of F along the ray in w = ln(B/B_free) from the node gradients, when u moves little along the ray
  const double fu = -((1 - sigma) * a.sn * a.tv + sigma * b.sn * b.tv);
  const double fv = (1 - sigma) * a.sn * a.tu + sigma * b.sn * b.tu;
  const double dq = dqc_du(h.u);
  double s0 = fv;
  if (contact_edge_ != 0.0) {
    const double du_dw = std::abs(dq) > 1e-3 ? contact_edge_ / (b_ref_ * std::exp(h.v)) / dq : 0.0;
    s0 = std::abs(dq) > 1e-3 ? fv + fu * du_dw : std::numeric_limits<double>::quiet_NaN();
  }
  auto at = [&](double w) {
    const double bb = b_ref_ * std::exp(w);
    return evaluate_gb(q * bb, bb);
  };
  Eval e0 = at(w0);
  if (!e0.ok) return false;
  if (!std::isfinite(s0)) {
    const Eval e1 = at(w0 + 1e-7);
    s0 = (e1.f - e0.f) / 1e-7;
  }
  const double limit = 4.0 * std::abs(b.e.v - a.e.v) + 0.05;
  Eval last = e0;
  auto f = [&](double dw) {
    last = at(w0 + dw);
    return last.ok ? last.f : std::numeric_limits<double>::quiet_NaN();
  };
  double root;
  int it;
  double s = s0;
  bool ok = secant(f, e0.f, s, limit, root, it, 2e-14 * (1.0 + std::abs(w0)));
  if (ok) {
    out = root == 0.0 ? e0 : last;
    slope = it > 0 ? s : ray_slope(out);
    return true;
  } else {
    // fallback: bracket on the ray around the segment and refine
    const double wlo = std::min(a.e.v, b.e.v) - 0.25 * std::abs(b.e.v - a.e.v) - 1e-3;
    const double whi = std::max(a.e.v, b.e.v) + 0.25 * std::abs(b.e.v - a.e.v) + 1e-3;
    const int n = 24;
    double best = std::numeric_limits<double>::infinity();
    double prev_w = wlo;
    Eval prev = at(wlo);
    for (int k = 1; k <= n; ++k) {
      const double w = wlo + (whi - wlo) * k / n;
      const Eval e = at(w);
      if (prev.ok && e.ok && prev.f * e.f <= 0.0) {
        std::uintmax_t iterations = 100;
        auto g = [&](double x) { return at(x).f; };
        const auto r = boost::math::tools::toms748_solve(g, prev_w, w, prev.f, e.f,
                                                         boost::math::tools::eps_tolerance<double>(52), iterations);
        const double wr = 0.5 * (r.first + r.second);
        if (std::abs(wr - w0) < best) {
          best = std::abs(wr - w0);
          out = at(wr);
          ok = out.ok;
        }
      }
      prev = e;
      prev_w = w;
    }
    if (!ok) return false;
  }
  slope = ray_slope(out);
  return true;
}

bool GeneralHarmonicBalance::solve_free_ray(double q, const Node& end, Eval& out, double& slope) const {
  auto at = [&](double w) {
    const double bb = b_ref_ * std::exp(w);
    return evaluate_gb(q * bb, bb);
  };
  const Eval e0 = at(end.e.v);
  if (!e0.ok) return false;
  const Eval e1 = at(end.e.v + 1e-7);
  Eval last = e0;
  auto f = [&](double dw) {
    last = at(end.e.v + dw);
    return last.ok ? last.f : std::numeric_limits<double>::quiet_NaN();
  };
  double root;
  int it;
  double s = (e1.f - e0.f) / 1e-7;
  if (!secant(f, e0.f, s, 1.0, root, it, 2e-14 * (1.0 + std::abs(end.e.v)))) return false;
  out = root == 0.0 ? e0 : last;
  slope = s;
  return out.ok;
}

// Beyond the far end of the free branch: fixed point l = g − A(g, B), F(g, B) = 0 (N1, ⟨h⟩ are negligible there).
bool GeneralHarmonicBalance::solve_free_separation(double l, const Node& end, Eval& out) const {
  double b = end.e.b;
  double offset = end.e.offset;
  for (int it = 0; it < 50; ++it) {
    const double g = l + offset;
    const double q = g / b;
    Eval e;
    double slope;
    Node n = end;
    n.e.v = std::log(b / b_ref_);
    if (!solve_free_ray(q, n, e, slope)) return false;
    const double change = std::abs(e.offset - offset) + std::abs(e.b - b);
    b = e.b;
    offset = e.offset;
    out = e;
    if (change <= 1e-15 * (std::abs(l) + b)) break;
  }
  return out.ok && std::abs(out.separation - l) <= 1e-12 * (std::abs(l) + b_ref_);
}

namespace {
void unique_sorted(std::vector<HbPoint>& points) {
  std::sort(points.begin(), points.end(), [](const HbPoint& a, const HbPoint& b) { return a.amplitude < b.amplitude; });
  std::vector<HbPoint> unique;
  for (const HbPoint& p : points) {
    const bool duplicate = std::any_of(unique.begin(), unique.end(), [&](const HbPoint& u) {
      return std::abs(u.q - p.q) <= 1e-10 * std::max(1.0, std::abs(p.q)) &&
             std::abs(u.amplitude - p.amplitude) <= 1e-9 * p.amplitude;
    });
    if (!duplicate) unique.push_back(p);
  }
  points = std::move(unique);
}
}  // namespace

std::optional<HbPoint> GeneralHarmonicBalance::segment_point(double q, const Node& a, const Node& b) const {
  const double qa = a.e.g / a.e.b, qb = b.e.g / b.e.b;
  Eval e;
  double slope;
  if (q == qa) {
    e = a.e;
    slope = ray_slope(e);
  } else if (q == qb) {
    e = b.e;
    slope = ray_slope(e);
  } else if (!solve_on_ray(q, a, b, e, slope)) {
    return std::nullopt;
  }
  HbPoint p = to_point(e, slope);
  p.q = q;  // the requested q exactly (g/B rounds)
  return p;
}

std::vector<HbPoint> GeneralHarmonicBalance::ray_points(double q, bool with_minus) const {
  std::vector<HbPoint> out;
  for (std::size_t ci = 0; ci < components_.size(); ++ci) {
    const auto& c = components_[ci];
    for (std::size_t k = 0; k + 1 < c.size(); ++k) {
      if (c[k].break_after) continue;
      const double qa = c[k].e.g / c[k].e.b, qb = c[k + 1].e.g / c[k + 1].e.b;
      if (!((qa <= q && q <= qb) || (qb <= q && q <= qa))) continue;
      const auto p = segment_point(q, c[k], c[k + 1]);
      if (p && (with_minus || p->branch != HbBranch::Minus)) out.push_back(*p);
    }
    if (free_end_[ci] && c.size() >= 2) {
      const double q0 = c[0].e.g / c[0].e.b, q1 = c[1].e.g / c[1].e.b;
      if ((q - q0) * (q0 - q1) > 0.0) {
        Eval e;
        double slope;
        if (solve_free_ray(q, c[0], e, slope)) {
          HbPoint p = to_point(e, slope);
          p.q = q;
          if (with_minus || p.branch != HbBranch::Minus) out.push_back(p);
        }
      }
    }
  }
  unique_sorted(out);
  return out;
}

std::vector<HbPoint> GeneralHarmonicBalance::points_at_q(double q) const {
  validate::finite("q", q);
  return ray_points(q, true);
}

void GeneralHarmonicBalance::sample(const std::vector<double>& qs, bool include_minus, std::vector<HbPoint>& upper,
                                    std::vector<HbPoint>& lower, const Cancellation& cancellation) const {
  // (sample index, point) pairs from every segment whose q range contains samples
  std::vector<std::pair<std::size_t, HbPoint>> found;
  std::size_t evaluated = 0;  // a cancellation check every 4096 evaluations
  for (std::size_t ci = 0; ci < components_.size(); ++ci) {
    const auto& c = components_[ci];
    for (std::size_t k = 0; k + 1 < c.size(); ++k) {
      if (c[k].break_after) continue;
      const double qa = c[k].e.g / c[k].e.b, qb = c[k + 1].e.g / c[k + 1].e.b;
      const double lo = std::min(qa, qb), hi = std::max(qa, qb);
      auto it = std::lower_bound(qs.begin(), qs.end(), lo);
      for (; it != qs.end() && *it <= hi; ++it) {
        if ((++evaluated & 4095) == 0) cancellation.check();
        const double q = *it;
        const auto p = segment_point(q, c[k], c[k + 1]);
        if (p && (include_minus || p->branch != HbBranch::Minus))
          found.emplace_back(static_cast<std::size_t>(it - qs.begin()), *p);
      }
    }
    if (free_end_[ci] && c.size() >= 2) {
      const double q0 = c[0].e.g / c[0].e.b, q1 = c[1].e.g / c[1].e.b;
      for (std::size_t s = 0; s < qs.size(); ++s) {
        if ((++evaluated & 4095) == 0) cancellation.check();
        if (!((qs[s] - q0) * (q0 - q1) > 0.0)) continue;
        Eval e;
        double slope;
        if (solve_free_ray(qs[s], c[0], e, slope)) {
          HbPoint p = to_point(e, slope);
          p.q = qs[s];
          found.emplace_back(s, p);
        }
      }
    }
  }
  // stable: points of equal sample and amplitude keep the order of the segments, so that sampling any contiguous
  // part of the samples gives the same points for it (the streamed curve samples chunk by chunk)
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first < b.first : a.second.amplitude < b.second.amplitude;
  });
  // drop duplicates (a sample on a node shared by two segments)
  for (std::size_t k = 0; k < found.size(); ++k) {
    const auto& [s, p] = found[k];
    bool duplicate = false;
    for (std::size_t j = k; j-- > 0 && found[j].first == s;)
      if (std::abs(found[j].second.amplitude - p.amplitude) <= 1e-9 * p.amplitude) duplicate = true;
    if (duplicate) continue;
    (p.branch == HbBranch::Minus ? lower : upper).push_back(p);
  }
}

std::vector<HbPoint> GeneralHarmonicBalance::solutions(double separation) const {
  validate::finite("separation", separation);
  const double l = separation;
  std::vector<HbPoint> out;
  for (std::size_t ci = 0; ci < components_.size(); ++ci) {
    const auto& c = components_[ci];
    for (std::size_t k = 0; k + 1 < c.size(); ++k) {
      if (c[k].break_after) continue;
      const Node& a = c[k];
      const Node& b = c[k + 1];
      const double fa = a.e.separation - l, fb = b.e.separation - l;
      if (fa == 0.0) out.push_back(to_point(a.e, ray_slope(a.e)));
      if (fb == 0.0) out.push_back(to_point(b.e, ray_slope(b.e)));
      if (!(fa * fb < 0.0)) continue;
      // along the curve: σ ↦ corrected point ↦ l − l*, bracketed on [0, 1]
      Eval best;
      bool ok = true;
      auto f = [&](double s) {
        Eval e;
        if (!point_on_segment(a, b, s, e)) throw NumericalFailure("harmonic balance: curve point not found");
        best = e;
        return e.separation - l;
      };
      try {
        std::uintmax_t iterations = 100;
        const auto r = boost::math::tools::toms748_solve(f, 0.0, 1.0, fa, fb,
                                                         boost::math::tools::eps_tolerance<double>(50), iterations);
        f(0.5 * (r.first + r.second));
      } catch (const NumericalFailure&) {
        ok = false;
      }
      if (ok && best.ok) out.push_back(to_point(best, ray_slope(best)));
    }
    if (free_end_[ci] && c.size() >= 2) {
      const double l0 = c[0].e.separation, l1 = c[1].e.separation;
      if ((l - l0) * (l0 - l1) > 0.0) {
        Eval e;
        if (solve_free_separation(l, c[0], e)) out.push_back(to_point(e, ray_slope(e)));
      }
    }
  }
  unique_sorted(out);
  return out;
}

}  // namespace afmkit::tapping::detail
