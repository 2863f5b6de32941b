#include "reference.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/quadrature/tanh_sinh.hpp>

namespace afmkit::tapping::test {

namespace {
using std::numbers::pi;

// Piecewise-linear pieces are polynomial in cos θ: GK31 is exact to rounding at depth 0–1 (depth 3 caps the work
// when 1e-14 is below the rounding of a large integrand); other laws get a deeper bisection.
template <class F>
double integrate(F f, double a, double b, unsigned depth = 3) {
  return boost::math::quadrature::gauss_kronrod<double, 31>::integrate(f, a, b, depth, 1e-14);
}
}  // namespace

// Angles in (0, 2π) where g + B cos θ crosses a switching gap of the law, found by bisection (independent of the
// library's closed-form switching angles).
std::vector<double> switching_cuts(const impact::ForceLaw& law, double g, double b) {
  std::vector<double> cuts{0.0, pi, 2.0 * pi};
  for (const double s : law.switching_gaps()) {
    if (!(s > g - b && s < g + b)) continue;
    double lo = 0.0, hi = pi;  // d(θ) decreasing on [0, π]
    for (int it = 0; it < 200 && hi - lo > 0.0; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (mid == lo || mid == hi) break;
      (g + b * std::cos(mid) > s ? lo : hi) = mid;
    }
    const double t = 0.5 * (lo + hi);
    cuts.push_back(t);
    cuts.push_back(2.0 * pi - t);
  }
  std::sort(cuts.begin(), cuts.end());
  return cuts;
}

QuadratureDf quadrature_df(const TappingModel& model, double offset, double amplitude) {
  const std::vector<double> cuts = switching_cuts(model.law, offset + model.separation, amplitude);
  auto h = [&](double theta) {
    const double x = offset + amplitude * std::cos(theta);
    const double velocity = -amplitude * model.drive.frequency * std::sin(theta);
    return model.interaction(x, velocity);
  };
  const unsigned depth = model.law.piecewise_linear() != nullptr ? 3 : 15;
  double m = 0, c = 0, s = 0;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    if (cuts[k + 1] <= cuts[k]) continue;
    m += integrate(h, cuts[k], cuts[k + 1], depth);
    c += integrate([&](double t) { return h(t) * std::cos(t); }, cuts[k], cuts[k + 1], depth);
    s += integrate([&](double t) { return h(t) * std::sin(t); }, cuts[k], cuts[k + 1], depth);
  }
  return {m / (2.0 * pi), std::complex<double>(c, -s) / (pi * amplitude)};
}

QuadratureDf tanh_sinh_df(const impact::ForceLaw& law, double mean_gap, double amplitude, double frequency) {
  const std::vector<double> cuts = switching_cuts(law, mean_gap, amplitude);
  auto h = [&](double theta) {
    return -law.force(mean_gap + amplitude * std::cos(theta), -amplitude * frequency * std::sin(theta));
  };
  static thread_local boost::math::quadrature::tanh_sinh<double> ts(15);
  double m = 0, c = 0, s = 0;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k], b = cuts[k + 1];
    if (!(b > a)) continue;
    // on the open interval (a, b): the rate never vanishes inside a piece, so the branch is the piece's own
    m += ts.integrate(h, a, b, 1e-15);
    c += ts.integrate([&](double t) { return h(t) * std::cos(t); }, a, b, 1e-15);
    s += ts.integrate([&](double t) { return h(t) * std::sin(t); }, a, b, 1e-15);
  }
  return {m / (2.0 * pi), std::complex<double>(c, -s) / (pi * amplitude)};
}

std::vector<double> balance_residual(const TappingModel& model, double offset, double amplitude, double phase) {
  const double gamma = model.drive.amplitude;
  const double l0 = model.cantilever.static_gain();
  const std::complex<double> inverse = 1.0 / model.cantilever.transfer({0.0, model.drive.frequency});
  const QuadratureDf df = quadrature_df(model, offset, amplitude);
  const std::complex<double> r = amplitude * (inverse + df.first) - gamma * std::polar(1.0, phase);
  return {(offset + l0 * df.mean) / (gamma * l0), r.real() / gamma, r.imag() / gamma};
}

std::optional<NewtonSolution> newton_solve(const TappingModel& model, double offset, double amplitude, double phase) {
  Eigen::Vector3d z(offset, amplitude, phase);
  auto residual = [&](const Eigen::Vector3d& v) {
    const auto r = balance_residual(model, v[0], std::abs(v[1]), v[2]);
    return Eigen::Vector3d(r[0], r[1], r[2]);
  };
  Eigen::Vector3d r = residual(z);
  for (int it = 0; it < 80; ++it) {
    if (r.cwiseAbs().maxCoeff() < 1e-12) break;
    Eigen::Matrix3d jac;
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-7 * std::max(1.0, std::abs(z[k]));
      Eigen::Vector3d zp = z, zm = z;
      zp[k] += h;
      zm[k] -= h;
      jac.col(k) = (residual(zp) - residual(zm)) / (2.0 * h);
    }
    const Eigen::Vector3d step = jac.fullPivLu().solve(-r);
    if (!step.allFinite()) return std::nullopt;
    double lambda = 1.0;
    bool accepted = false;
    for (int k = 0; k < 30; ++k, lambda *= 0.5) {
      const Eigen::Vector3d trial = z + lambda * step;
      const Eigen::Vector3d rt = residual(trial);
      if (rt.norm() < (1.0 - 1e-4 * lambda) * r.norm() || rt.cwiseAbs().maxCoeff() < 1e-12) {
        z = trial;
        r = rt;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
  }
  const double res = r.cwiseAbs().maxCoeff();
  if (!(res < 1e-11)) return std::nullopt;
  return NewtonSolution{z[0], std::abs(z[1]), std::remainder(z[2], 2.0 * pi), res};
}

}  // namespace afmkit::tapping::test
