#include "afmkit/spectroscopy/hertz_fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <unsupported/Eigen/NonLinearOptimization>

#include "afmkit/core/error.hpp"

namespace afmkit::spectroscopy {

const char* to_string(ContactModel model) { return model == ContactModel::dmt ? "dmt" : "hertz"; }

namespace {

/// Residuals of the scaled model f(u) = p1·max(0, p0 − u)^{3/2} (+ p2 for DMT) minus the scaled forces, and their
/// Jacobian (the functor Eigen's MINPACK port expects).
struct ScaledHertz {
  const std::vector<double>& u;
  const std::vector<double>& f;
  bool dmt;
  int inputs() const { return dmt ? 3 : 2; }
  int values() const { return static_cast<int>(u.size()); }
  int operator()(const Eigen::VectorXd& p, Eigen::VectorXd& r) const {
    for (std::size_t i = 0; i < u.size(); ++i) {
      const double d = std::max(0.0, p[0] - u[i]);
      r[static_cast<Eigen::Index>(i)] = p[1] * d * std::sqrt(d) + (dmt ? p[2] : 0.0) - f[i];
    }
    return 0;
  }
  int df(const Eigen::VectorXd& p, Eigen::MatrixXd& j) const {
    for (std::size_t i = 0; i < u.size(); ++i) {
      const auto k = static_cast<Eigen::Index>(i);
      const double d = std::max(0.0, p[0] - u[i]), s = std::sqrt(d);
      j(k, 0) = 1.5 * p[1] * s;
      j(k, 1) = d * s;
      if (dmt) j(k, 2) = 1.0;
    }
    return 0;
  }
};

const char* status_text(int status) {
  switch (status) {
    case 1: return "relative reduction of the sum of squares below ftol";
    case 2: return "relative change of the parameters below xtol";
    case 3: return "sum of squares and parameters converged";
    case 4: return "residuals orthogonal to the Jacobian (gtol)";
    case 5: return "too many function evaluations";
    case 6: return "ftol too small: no further reduction possible";
    case 7: return "xtol too small: no further improvement possible";
    case 8: return "gtol too small: residuals orthogonal to the Jacobian to machine precision";
    default: return "improper input parameters";
  }
}

}  // namespace

HertzFit fit_hertz(const std::vector<double>& position, const std::vector<double>& force, double contact_guess,
                   const HertzFitOptions& options) {
  if (!std::isnan(options.tip_radius) && !(options.tip_radius > 0 && std::isfinite(options.tip_radius)))
    throw InvalidParameter("tip_radius", fmt::format("tip_radius = {} m is out of range: must be > 0", options.tip_radius));
  if (!(options.poisson_ratio >= 0 && options.poisson_ratio <= 0.5))
    throw InvalidParameter("poisson_ratio",
                           fmt::format("poisson_ratio = {} is out of range: must be in [0, 0.5]", options.poisson_ratio));
  const bool dmt = options.model == ContactModel::dmt;
  const std::size_t n = position.size(), unknowns = dmt ? 3 : 2;
  const char* name = dmt ? "DMT fit" : "Hertz fit";
  if (n < 2 * unknowns || force.size() != n)
    throw NumericalFailure(fmt::format("{}: {} samples in the fit range, fewer than {} (2 per unknown)", name, n,
                                       2 * unknowns));
  const auto [xlo, xhi] = std::minmax_element(position.begin(), position.end());
  const double length = std::max(*xhi - *xlo, 1e-300);
  double fmax = 0;
  for (double v : force) fmax = std::max(fmax, std::abs(v));
  const double scale = fmax > 0 ? fmax : 1.0;
  std::vector<double> u(n), f(n);
  std::size_t deepest = 0;
  for (std::size_t i = 0; i < n; ++i) {
    u[i] = (position[i] - contact_guess) / length;
    f[i] = force[i] / scale;
    if (position[i] < position[deepest]) deepest = i;
  }
  // start: the guess, the offset of the samples out of contact (DMT: the lowest force), C through the deepest sample
  Eigen::VectorXd p(static_cast<Eigen::Index>(unknowns));
  p[0] = 0.0;
  const double f0 = dmt ? *std::min_element(f.begin(), f.end()) : 0.0;
  const double dmax = std::max(-u[deepest], 1e-6);
  p[1] = std::max((f[deepest] - f0) / (dmax * std::sqrt(dmax)), 1e-6);
  if (dmt) p[2] = f0;

  ScaledHertz functor{u, f, dmt};
  Eigen::LevenbergMarquardt<ScaledHertz> lm(functor);
  lm.parameters.maxfev = 400 * static_cast<int>(unknowns + 1);
  lm.parameters.xtol = 1e-12;
  lm.parameters.ftol = 1e-14;
  const int status = static_cast<int>(lm.minimize(p));
  HertzFit fit;
  fit.model = options.model;
  fit.points = n;
  fit.position_from = *xlo;
  fit.position_to = *xhi;
  fit.evaluations = static_cast<int>(lm.nfev);
  fit.solver_status = status_text(status);
  if (status < 1 || status == 5 || !p.allFinite())
    throw NumericalFailure(fmt::format("{}: Levenberg–Marquardt failed after {} evaluations: {}", name, lm.nfev,
                                       status_text(status)));
  std::size_t indented = 0;
  for (double ui : u) indented += ui < p[0] ? 1 : 0;
  if (!(p[1] > 0) || indented < unknowns)
    throw NumericalFailure(fmt::format("{}: no contact at the solution ({} samples indented, coefficient {:.3g}): the "
                                       "approach in the fit range does not look like an indentation",
                                       name, indented, p[1] * scale / std::pow(length, 1.5)));
  // the contact point may lie beyond the samples (DMT: the snap-in jumps past it), but not by more than their span
  if (p[0] < (*xlo - contact_guess) / length - 1 || p[0] > (*xhi - contact_guess) / length + 1)
    throw NumericalFailure(fmt::format("{}: the fitted contact point {:.6g} µm lies far outside the fitted samples "
                                       "({:.6g} to {:.6g} µm): the approach there does not look like a {} indentation",
                                       name, (contact_guess + length * p[0]) * 1e6, *xlo * 1e6, *xhi * 1e6,
                                       dmt ? "DMT" : "Hertz"));
  Eigen::VectorXd r(static_cast<Eigen::Index>(n));
  Eigen::MatrixXd j(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(unknowns));
  functor(p, r);
  functor.df(p, j);
  const double variance = r.squaredNorm() / static_cast<double>(n - unknowns);
  const Eigen::MatrixXd jtj = j.transpose() * j;
  const Eigen::MatrixXd cov = variance * jtj.ldlt().solve(Eigen::MatrixXd::Identity(jtj.rows(), jtj.cols()));
  fit.contact_point = contact_guess + length * p[0];
  fit.contact_point_error = length * std::sqrt(std::max(cov(0, 0), 0.0));
  const double cscale = scale / (length * std::sqrt(length));
  fit.coefficient = p[1] * cscale;
  fit.coefficient_error = std::sqrt(std::max(cov(1, 1), 0.0)) * cscale;
  if (dmt) {
    fit.offset = p[2] * scale;
    fit.offset_error = std::sqrt(std::max(cov(2, 2), 0.0)) * scale;
  }
  fit.residual_rms = std::sqrt(variance) * scale;
  if (!std::isnan(options.tip_radius)) {
    // F = (4/3) E/(1 − ν²) √R δ^{3/2}  →  E = 3 C (1 − ν²) / (4 √R)
    const double factor = 3.0 * (1.0 - options.poisson_ratio * options.poisson_ratio) / (4.0 * std::sqrt(options.tip_radius));
    fit.youngs_modulus = factor * fit.coefficient;
    fit.youngs_modulus_error = factor * fit.coefficient_error;
  }
  return fit;
}

}  // namespace afmkit::spectroscopy
