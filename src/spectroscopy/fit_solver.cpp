// `spectroscopy fit`: the parts of the least-squares engine (fit_engine.hpp) that are not templates — noise
// estimate, the solver's status in words, standard errors, correlations and identifiability (docs/fitting.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/NonLinearOptimization>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/numbers.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"
#include "fit_engine.hpp"

namespace afmkit::spectroscopy::engine {

namespace {

constexpr double kPi = 3.14159265358979323846;
using afmkit::numbers::infinity;
using afmkit::numbers::nan;

}  // namespace

/// x wrapped to (−π, π].
double wrap(double x) {
  x = std::remainder(x, 2.0 * kPi);
  return x <= -kPi ? x + 2.0 * kPi : x;
}

/// The data's noise about a smooth curve: 1.4826 · median |second difference| / √6 (a second difference of white
/// noise has variance 6σ²; the median ignores the few differences across a jump or a corner).
double scatter(const std::vector<double>& y, bool angle) {
  std::vector<double> d;
  for (std::size_t i = 1; i + 1 < y.size(); ++i) {
    const double a = angle ? wrap(y[i + 1] - y[i]) : y[i + 1] - y[i];
    const double b = angle ? wrap(y[i] - y[i - 1]) : y[i] - y[i - 1];
    d.push_back(std::abs(a - b));
  }
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return 1.4826 * d[d.size() / 2] / std::sqrt(6.0);
}

std::string solver_status_text(int s) {
  switch (s) {
    case Eigen::LevenbergMarquardtSpace::ImproperInputParameters: return "improper input parameters";
    case Eigen::LevenbergMarquardtSpace::RelativeReductionTooSmall: return "relative reduction of the cost below ftol";
    case Eigen::LevenbergMarquardtSpace::RelativeErrorTooSmall: return "relative step below xtol";
    case Eigen::LevenbergMarquardtSpace::RelativeErrorAndReductionTooSmall:
      return "relative reduction below ftol and relative step below xtol";
    case Eigen::LevenbergMarquardtSpace::CosinusTooSmall: return "gradient orthogonal to the residuals (gtol)";
    case Eigen::LevenbergMarquardtSpace::TooManyFunctionEvaluation: return "evaluation budget spent";
    case Eigen::LevenbergMarquardtSpace::FtolTooSmall: return "ftol too small: no further reduction possible";
    case Eigen::LevenbergMarquardtSpace::XtolTooSmall: return "xtol too small: no further improvement possible";
    case Eigen::LevenbergMarquardtSpace::GtolTooSmall: return "gtol too small";
    case Eigen::LevenbergMarquardtSpace::UserAsked: return "evaluation budget (max_evaluations) spent";
    default: return fmt::format("status {}", s);
  }
}

/// Covariance, correlations and identifiability from the weighted Jacobian J (in u) at the estimates.
void statistics(const Eigen::MatrixXd& jac, double s2, const Eigen::VectorXd& u, const FitOptions& options,
                FitResult& r) {
  const long p = jac.cols();
  const Eigen::MatrixXd h = jac.transpose() * jac;
  Eigen::VectorXd d(p);
  for (long j = 0; j < p; ++j) d[j] = std::sqrt(h(j, j));
  const double dmax = d.maxCoeff();
  std::vector<long> live;  // parameters the data depend on
  r.identifiable.assign(static_cast<std::size_t>(p), true);
  for (long j = 0; j < p; ++j) {
    // flat: a change of u by 1 (a factor e of a law parameter, 1 nm of offset, 1 rad of phase) moves the weighted
    // residuals by less than flat_column (in units of the noise): what is left is the orbits' rounding
    if (!(d[j] > options.flat_column) || !(d[j] > 1e-12 * dmax)) {
      r.identifiable[static_cast<std::size_t>(j)] = false;
      r.warnings.push_back(fmt::format("{} is not identifiable: the fitted curve does not depend on it (flat cost: "
                                       "the norm of its weighted Jacobian column is {:.2g} < {:.2g}{})",
                                       r.parameters[static_cast<std::size_t>(j)].name, d[j], options.flat_column,
                                       r.parameters[static_cast<std::size_t>(j)].name == "effective_modulus" ||
                                               r.parameters[static_cast<std::size_t>(j)].name == "departure_modulus"
                                           ? "; the tip never reaches the contact gap"
                                           : ""));
    } else {
      live.push_back(j);
    }
  }
  const long q = static_cast<long>(live.size());
  Eigen::MatrixXd cov_u = Eigen::MatrixXd::Constant(p, p, nan);
  r.condition_number = infinity;
  if (q > 0) {
    Eigen::MatrixXd scaled(q, q);  // unit diagonal: D⁻¹ H D⁻¹
    for (long a = 0; a < q; ++a)
      for (long b = 0; b < q; ++b) scaled(a, b) = h(live[a], live[b]) / (d[live[a]] * d[live[b]]);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(scaled);
    const Eigen::VectorXd lam = es.eigenvalues();  // ascending
    r.condition_number = lam[0] > 0.0 ? lam[q - 1] / lam[0] : infinity;
    if (!(r.condition_number <= options.condition_limit)) {
      const Eigen::VectorXd v = es.eigenvectors().col(0);
      std::string names;
      for (long a = 0; a < q; ++a)
        if (std::abs(v[a]) > 0.3)
          names += (names.empty() ? "" : ", ") + r.parameters[static_cast<std::size_t>(live[a])].name;
      r.warnings.push_back(fmt::format("JᵀWJ is near-singular (condition number {:.3g} > {:.3g}): the cost is flat "
                                       "along a combination of {} (not identifiable together)",
                                       r.condition_number, options.condition_limit, names));
    }
    // pseudo-inverse of the scaled matrix (eigenvalues below 1e-14 of the largest dropped: infinite variance)
    Eigen::MatrixXd inv = Eigen::MatrixXd::Zero(q, q);
    bool dropped = false;
    for (long k = 0; k < q; ++k) {
      if (lam[k] > 1e-14 * lam[q - 1]) inv += es.eigenvectors().col(k) * es.eigenvectors().col(k).transpose() / lam[k];
      else dropped = true;
    }
    for (long a = 0; a < q; ++a)
      for (long b = 0; b < q; ++b) cov_u(live[a], live[b]) = s2 * inv(a, b) / (d[live[a]] * d[live[b]]);
    if (dropped) {  // a direction of exactly flat cost: the parameters in it have unbounded variance
      for (long k = 0; k < q; ++k)
        if (!(lam[k] > 1e-14 * lam[q - 1]))
          for (long a = 0; a < q; ++a)
            if (std::abs(es.eigenvectors()(a, k)) > 1e-6) cov_u(live[a], live[a]) = infinity;
    }
  }
  r.standard_errors.assign(static_cast<std::size_t>(p), infinity);
  r.correlation.assign(static_cast<std::size_t>(p), std::vector<double>(static_cast<std::size_t>(p), nan));
  for (long a = 0; a < p; ++a) {
    const auto sa = static_cast<std::size_t>(a);
    const double da = parameter_derivative(r.parameters[sa], u[a]);
    if (r.identifiable[sa]) r.standard_errors[sa] = std::sqrt(cov_u(a, a)) * std::abs(da);
    for (long b = 0; b < p; ++b) {
      const auto sb = static_cast<std::size_t>(b);
      if (r.identifiable[sa] && r.identifiable[sb] && std::isfinite(cov_u(a, a)) && std::isfinite(cov_u(b, b)))
        r.correlation[sa][sb] = a == b ? 1.0 : cov_u(a, b) / std::sqrt(cov_u(a, a) * cov_u(b, b));
    }
  }
  for (long a = 0; a < p; ++a)
    for (long b = a + 1; b < p; ++b) {
      const double c = r.correlation[static_cast<std::size_t>(a)][static_cast<std::size_t>(b)];
      if (std::abs(c) > options.correlation_limit)
        r.warnings.push_back(fmt::format("{} and {} are correlated {:+.4f} (|correlation| > {}): not separately "
                                         "identifiable from these data",
                                         r.parameters[static_cast<std::size_t>(a)].name,
                                         r.parameters[static_cast<std::size_t>(b)].name, c, options.correlation_limit));
    }
  for (long a = 0; a < p; ++a) {
    const auto sa = static_cast<std::size_t>(a);
    // an offset (identity transform) may be 0 at the truth: compared with its scale too (1 nm, 1 rad)
    const double size = r.parameters[sa].transform == Transform::identity
                            ? std::max(std::abs(r.estimates[sa]), r.parameters[sa].scale)
                            : std::abs(r.estimates[sa]);
    if (r.identifiable[sa] && !(r.standard_errors[sa] <= size))
      r.warnings.push_back(fmt::format("{}: the standard error ({:.3g} {}) exceeds the estimate ({:.3g} {}): poorly "
                                       "determined",
                                       r.parameters[sa].name, r.standard_errors[sa], r.parameters[sa].unit,
                                       r.estimates[sa], r.parameters[sa].unit));
  }
}

std::vector<std::size_t> sweep_order(const std::vector<double>& distance, CurveDirection direction) {
  std::vector<std::size_t> idx(distance.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return direction == CurveDirection::approach ? distance[a] > distance[b] : distance[a] < distance[b];
  });
  return idx;
}

std::vector<double> in_order(const std::vector<double>& values, const std::vector<std::size_t>& order) {
  std::vector<double> out;
  if (values.empty()) return out;
  for (std::size_t i : order) out.push_back(values[i]);
  return out;
}

std::map<std::string, double> law_values_used(const std::string& law_name, const std::map<std::string, double>& law) {
  const impact::LawRegistry registry = impact::LawRegistry::builtin();
  impact::LawArguments args;
  for (const auto& [k, x] : law)
    for (const auto& d : registry.keys())
      if (d.key == k) args.values[k] = x / law_unit_to_si(d.unit);
  std::map<std::string, double> out = law;
  for (const std::string& key : registry.find(law_name).keys)
    for (const auto& d : registry.keys())
      if (d.key == key && (!d.only_if_given || args.given(key)))
        out[key] = args.real(d, registry.keys()) * law_unit_to_si(d.unit);
  return out;
}

}  // namespace afmkit::spectroscopy::engine
