// Describing functions of any force law by Gauss–Kronrod quadrature split at the switching angles.
#include "afmkit/tapping/numerical_describing_functions.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"

namespace afmkit::tapping {

namespace {

using std::numbers::pi;  // (a using-declaration: repeatable in a unity build)
constexpr int rule_points = 31;  // Kronrod nodes per panel (the 15-point Gauss rule embedded)
constexpr int rule_half = (rule_points + 1) / 2;  // abscissae x_0 = 0 < x_1 < … (each ±)
constexpr int hard_panel_limit = 1024;

struct Rule {
  std::array<double, rule_half> x;
  std::array<double, rule_half> kronrod;
  std::array<double, rule_half> gauss;  // 0 where x is not a Gauss node
};

const Rule& rule() {
  static const Rule r = [] {
    Rule out{};
    const auto& xk = boost::math::quadrature::gauss_kronrod<double, rule_points>::abscissa();
    const auto& wk = boost::math::quadrature::gauss_kronrod<double, rule_points>::weights();
    const auto& xg = boost::math::quadrature::gauss<double, rule_points / 2>::abscissa();
    const auto& wg = boost::math::quadrature::gauss<double, rule_points / 2>::weights();
    for (int i = 0; i < rule_half; ++i) {
      out.x[i] = xk[i];
      out.kronrod[i] = wk[i];
      out.gauss[i] = 0.0;
      for (std::size_t j = 0; j < xg.size(); ++j)
        if (std::abs(xg[j] - xk[i]) < 1e-14) out.gauss[i] = wg[j];
    }
    return out;
  }();
  return r;
}

// Change of variable θ(τ), τ ∈ [0, 1], on a piece [lo, hi]: smooths endpoint singularities at switching angles.
enum class Map { Linear, Left, Right, Both };

// An end of a piece: angle θ_e, cos θ_e, sin θ_e and the gap d(θ_e) (a switching gap exactly, or g ± B). The gap
// inside the piece is formed as d_e + B(cos θ − cos θ_e) from the offset δ = θ − θ_e given by the map, so that a
// tiny penetration next to a switching gap is not lost to the rounding of g + B cos θ.
struct End {
  double theta, cos, sin, gap;
};

struct Piece {
  double lo, hi;
  Map map;
  bool branches;  // H_a and H_b may differ on this piece
  End lo_end, hi_end;
};

struct Panel {
  int piece;
  double t0, t1;
  std::array<double, 3> value;  // Kronrod estimates of the three integrals
  double error;                 // summed QUADPACK error estimate
  double absolute;              // ∫ |S| + |D'|
};

// θ(τ) on a piece as an offset δ from one of its ends (hi_end = true: from hi), and dθ/dτ.
inline void map_point(const Piece& p, double tau, bool& from_hi, double& delta, double& jacobian) {
  const double len = p.hi - p.lo;
  switch (p.map) {
    case Map::Linear:
      from_hi = false;
      delta = len * tau;
      jacobian = len;
      return;
    case Map::Left:
      from_hi = false;
      delta = len * tau * tau;
      jacobian = 2.0 * len * tau;
      return;
    case Map::Right: {
      const double r = 1.0 - tau;
      from_hi = true;
      delta = -len * r * r;
      jacobian = 2.0 * len * r;
      return;
    }
    case Map::Both: {  // θ − lo = L τ²(3 − 2τ) (symmetric: hi − θ = L (1−τ)²(1 + 2τ))
      from_hi = tau > 0.5;
      const double t = from_hi ? 1.0 - tau : tau;
      delta = (from_hi ? -len : len) * t * t * (3.0 - 2.0 * t);
      jacobian = 6.0 * len * tau * (1.0 - tau);
      return;
    }
  }
}

// QUADPACK (qk31) error scaling of |K − G| with the spread of the integrand.
inline double quadpack_error(double difference, double resasc, double resabs) {
  double err = std::abs(difference);
  if (resasc != 0.0 && err != 0.0) err = resasc * std::min(1.0, std::pow(200.0 * err / resasc, 1.5));
  constexpr double eps = std::numeric_limits<double>::epsilon();
  if (resabs > std::numeric_limits<double>::min() / (50.0 * eps)) err = std::max(50.0 * eps * resabs, err);
  return err;
}

struct Evaluator {
  const impact::ForceLaw& law;
  double gap;        // mean gap g
  double amplitude;  // B
  double rate;       // 2Bω (velocity-term factor)
  bool damping;
  int evaluations = 0;

  // The three integrands at θ = θ_e + δ (and |S| + |D'|).
  inline void operator()(const End& end, double delta, bool branches, double (&f)[3], double& absolute) {
    const double cd = std::cos(delta), sd = std::sin(delta);
    const double cm1 = cd < 0.0 ? cd - 1.0 : -sd * sd / (1.0 + cd);  // cos δ − 1 without cancellation
    const double c = end.cos * cd - end.sin * sd;                     // cos θ
    const double s = end.sin * cd + end.cos * sd;                     // sin θ
    const double d = end.gap + amplitude * (end.cos * cm1 - end.sin * sd);
    const double ha = law.approach(d);
    double sum, diff;
    if (branches) {
      const double hb = law.departure(d);
      sum = ha + hb;
      diff = ha - hb;
      evaluations += 2;
    } else {
      sum = 2.0 * ha;
      diff = 0.0;
      evaluations += 1;
    }
    if (damping) {
      diff += rate * law.damping(d) * s;
      evaluations += 1;
    }
    f[0] = sum;
    f[1] = sum * c;
    f[2] = diff * s;
    absolute = std::abs(sum) + std::abs(diff);
  }

  void integrate(const Piece& piece, int index, double t0, double t1, Panel& out) {
    const Rule& r = rule();
    const double half = 0.5 * (t1 - t0);
    const double mid = 0.5 * (t0 + t1);
    double values[2 * rule_half][3];
    double kron[3] = {0, 0, 0}, gauss[3] = {0, 0, 0};
    double absolute = 0;
    int n = 0;
    for (int i = 0; i < rule_half; ++i) {
      for (int side = 0; side < (i == 0 ? 1 : 2); ++side) {
        const double tau = side == 0 ? mid + half * r.x[i] : mid - half * r.x[i];
        bool from_hi = false;
        double delta = 0.0, jac = 0.0;
        map_point(piece, tau, from_hi, delta, jac);
        double f[3], a;
        (*this)(from_hi ? piece.hi_end : piece.lo_end, delta, piece.branches, f, a);
        for (int k = 0; k < 3; ++k) {
          values[n][k] = f[k] * jac;
          kron[k] += r.kronrod[i] * values[n][k];
          gauss[k] += r.gauss[i] * values[n][k];
        }
        absolute += r.kronrod[i] * a * jac;
        ++n;
      }
    }
    out.piece = index;
    out.t0 = t0;
    out.t1 = t1;
    out.error = 0.0;
    const double h = std::abs(half);
    for (int k = 0; k < 3; ++k) {
      const double mean = 0.5 * kron[k];
      double resasc = 0.0, resabs = 0.0;
      n = 0;
      for (int i = 0; i < rule_half; ++i) {
        for (int side = 0; side < (i == 0 ? 1 : 2); ++side, ++n) {
          resasc += r.kronrod[i] * std::abs(values[n][k] - mean);
          resabs += r.kronrod[i] * std::abs(values[n][k]);
        }
      }
      out.value[k] = kron[k] * half;
      out.error += quadpack_error((kron[k] - gauss[k]) * half, resasc * h, resabs * h);
    }
    out.absolute = absolute * h;
  }
};

// Angle θ ∈ (0, π) where g + B cos θ = s, for g − B < s < g + B; from the half-angle form near either end.
End switching_end(double gap, double amplitude, double s) {
  const double above = ((gap - s) + amplitude) / amplitude;  // 1 − cos θ_s
  const double below = ((s - gap) + amplitude) / amplitude;  // 1 + cos θ_s
  const double theta = above <= below ? 2.0 * std::asin(std::min(1.0, std::sqrt(0.5 * above)))
                                      : pi - 2.0 * std::asin(std::min(1.0, std::sqrt(0.5 * below)));
  return {theta, (s - gap) / amplitude, std::sqrt(std::max(0.0, above * below)), s};
}

}  // namespace

void NumericalDfOptions::validate() const {
  validate::require(relative_tolerance > 0.0 && relative_tolerance < 1.0, "relative_tolerance", relative_tolerance,
                    "in (0, 1)");
  validate::require(max_panels >= 1 && max_panels <= hard_panel_limit, "max_panels", max_panels,
                    "in [1, 1024]");
}

DescribingFunctionQuadrature::DescribingFunctionQuadrature(impact::ForceLaw law, double frequency,
                                                           NumericalDfOptions options)
    : law_(std::move(law)), frequency_(frequency), options_(options), gaps_(law_.switching_gaps()) {
  validate::positive("frequency", frequency);
  options_.validate();
  std::sort(gaps_.begin(), gaps_.end());
}

DescribingFunctions DescribingFunctionQuadrature::at_gap(double mean_gap, double amplitude,
                                                         NumericalDfInfo* info) const {
  if (!std::isfinite(mean_gap)) validate::finite("mean_gap", mean_gap);
  if (!(amplitude > 0.0 && std::isfinite(amplitude))) validate::positive("amplitude", amplitude);
  const double g = mean_gap, b = amplitude;

  // Switching angles (ascending θ = descending gap) and the pieces between them.
  const int n_gaps = static_cast<int>(gaps_.size());
  constexpr int max_local = 16;
  End ends_local[max_local];
  std::vector<End> ends_heap;
  End* ends = ends_local;
  if (n_gaps + 2 > max_local) {
    ends_heap.resize(n_gaps + 2);
    ends = ends_heap.data();
  }
  int n_ends = 0;
  ends[n_ends++] = {0.0, 1.0, 0.0, g + b};
  for (int k = n_gaps - 1; k >= 0; --k) {  // descending gap = ascending θ
    const double s = gaps_[k];
    if (s > g - b && s < g + b) ends[n_ends++] = switching_end(g, b, s);
  }
  ends[n_ends++] = {pi, -1.0, 0.0, g - b};
  std::sort(ends, ends + n_ends, [](const End& x, const End& y) { return x.theta < y.theta; });

  // A contact-aware law (docs/force-laws.md#hysteresis) over the cycle d = g + B cos θ: a cycle that reaches the
  // contact gap (g − B ≤ d_c) is in contact from there on the way down, unloads on H_b and is released above d_r,
  // where H_a = H_b — exactly the velocity-sign law; a cycle that does not reach it stays free: H_a throughout.
  const bool touched = !law_.contact_aware() || g - b <= law_.contact_gap();
  std::vector<Piece> pieces;
  pieces.reserve(n_ends);
  for (int k = 0; k + 1 < n_ends; ++k) {
    const double lo = ends[k].theta, hi = ends[k + 1].theta;
    if (!(hi > lo)) continue;
    const bool left = k > 0, right = k + 2 < n_ends;
    const Map map = left && right ? Map::Both : left ? Map::Left : right ? Map::Right : Map::Linear;
    const double d_mid = g + b * std::cos(0.5 * (lo + hi));
    const int region = static_cast<int>(std::upper_bound(gaps_.begin(), gaps_.end(), d_mid) - gaps_.begin());
    pieces.push_back({lo, hi, map, touched && law_.branch_dependent(region), ends[k], ends[k + 1]});
  }

  Evaluator ev{law_, g, b, 2.0 * b * frequency_, law_.has_damping()};
  std::vector<Panel> panels(pieces.size());
  for (std::size_t k = 0; k < pieces.size(); ++k) ev.integrate(pieces[k], static_cast<int>(k), 0.0, 1.0, panels[k]);

  auto totals = [&](double& err, double& scale) {
    err = 0.0;
    scale = 0.0;
    for (const Panel& p : panels) {
      err += p.error;
      scale += p.absolute;
    }
  };
  double err, scale;
  totals(err, scale);
  const std::size_t limit = std::max<std::size_t>(pieces.size(), static_cast<std::size_t>(options_.max_panels));
  while (err > options_.relative_tolerance * scale && panels.size() < limit && std::isfinite(err)) {
    std::size_t worst = 0;
    for (std::size_t k = 1; k < panels.size(); ++k)
      if (panels[k].error > panels[worst].error) worst = k;
    const Panel p = panels[worst];
    const double split = 0.5 * (p.t0 + p.t1);
    if (!(split > p.t0 && split < p.t1)) break;
    Panel right;
    ev.integrate(pieces[p.piece], p.piece, p.t0, split, panels[worst]);
    ev.integrate(pieces[p.piece], p.piece, split, p.t1, right);
    panels.push_back(right);
    totals(err, scale);
  }

  double integral[3] = {0, 0, 0};
  for (const Panel& p : panels)
    for (int k = 0; k < 3; ++k) integral[k] += p.value[k];
  if (info != nullptr) {
    info->panels = static_cast<int>(panels.size());
    info->law_evaluations = ev.evaluations;
    info->error_estimate = err;
    info->scale = scale;
    info->converged = err <= options_.relative_tolerance * scale;
  }
  return {-integral[0] / (2.0 * pi), std::complex<double>(-integral[1], integral[2]) / (pi * b)};
}

DescribingFunctions numerical_describing_functions(const impact::ForceLaw& law, double offset, double amplitude,
                                                   double separation, double frequency,
                                                   const NumericalDfOptions& options) {
  validate::finite("offset", offset);
  validate::finite("separation", separation);
  return DescribingFunctionQuadrature(law, frequency, options).at_gap(offset + separation, amplitude);
}

}  // namespace afmkit::tapping
