// `spectroscopy fit`: weighted nonlinear least squares over afmkit's periodic orbits by Eigen's Levenberg–Marquardt
// (MINPACK lmder), standard errors, correlations and identifiability (docs/fitting.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/NonLinearOptimization>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/impact/law_registry.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"

namespace afmkit::spectroscopy {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double inf = std::numeric_limits<double>::infinity();
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

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

/// The problem as the solver sees it: u -> weighted residuals.
class Problem {
 public:
  Problem(const FitCurve& sorted, const FitSettings& settings, const FitOptions& options,
          std::vector<FitParameterInfo> params, double sigma_a, double sigma_p)
      : data_(sorted), settings_(settings), options_(options), params_(std::move(params)), sigma_a_(sigma_a),
        sigma_p_(sigma_p), model_(settings, options, sorted.distance) {}

  long size() const { return static_cast<long>(data_.distance.size() * (data_.phase.empty() ? 1 : 2)); }
  long count() const { return static_cast<long>(params_.size()); }
  const AmForwardModel& model() const { return model_; }
  const std::vector<FitParameterInfo>& params() const { return params_; }

  ModelValues values(const Eigen::VectorXd& u) const {
    ModelValues v;
    v.law = options_.law_values;
    v.distance_offset = calibration_value(options_, "distance_offset");
    v.amplitude_scale = calibration_value(options_, "amplitude_scale");
    v.phase_offset = calibration_value(options_, "phase_offset");
    for (std::size_t j = 0; j < params_.size(); ++j) {
      const double p = to_parameter(params_[j], u[static_cast<long>(j)]);
      const std::string& name = params_[j].name;
      if (name == "distance_offset") v.distance_offset = p;
      else if (name == "amplitude_scale") v.amplitude_scale = p;
      else if (name == "phase_offset") v.phase_offset = p;
      else v.law[name] = p;
    }
    return v;
  }

  Eigen::VectorXd residuals(const CurveEvaluation& e, const ModelValues& v) const {
    const std::size_t n = data_.distance.size();
    Eigen::VectorXd r(size());
    const double a0 = settings_.free_amplitude;
    for (std::size_t i = 0; i < n; ++i) {
      r[static_cast<long>(i)] = robust((data_.amplitude[i] - e.amplitude[i] / v.amplitude_scale) / a0 / sigma_a_);
      if (!data_.phase.empty())
        r[static_cast<long>(n + i)] = robust(wrap(data_.phase[i] - e.phase[i] - v.phase_offset) / sigma_p_);
    }
    return r;
  }

  /// Huber's loss as a residual: r for |r| ≤ c, sign(r)·√(2c|r| − c²) beyond (Σ r'² is Huber's cost), c =
  /// options.huber noise units; 0: plain least squares. A point the model puts on another branch than the data
  /// (next to a jump, hundreds of σ off in phase) then pulls linearly, not quadratically.
  double robust(double x) const {
    const double c = options_.huber;
    if (c <= 0.0 || std::abs(x) <= c) return x;
    return std::copysign(std::sqrt(2.0 * c * std::abs(x) - c * c), x);
  }

  /// The evaluation at u (cached: the solver asks for the Jacobian where it evaluated the residuals).
  const CurveEvaluation* evaluate(const Eigen::VectorXd& u) {
    for (const auto& [x, e] : cache_)
      if (x.size() == u.size() && x == u) return &e;
    const ModelValues v = values(u);
    CurveEvaluation e;
    try {
      // warm started from the best evaluation so far (the solver's current point), else the whole sweep
      e = best_ ? model_.warm(v, *best_) : model_.walk(v);
    } catch (const InvalidParameter& ex) {  // a trial outside a law's valid set (e.g. energy gain)
      e.ok = false;
      e.error = ex.what();
    } catch (const NumericalFailure& ex) {
      e.ok = false;
      e.error = ex.what();
    }
    if (!e.ok) {
      ++failed_;
      last_error_ = e.error;
    }
    if (e.ok) {
      const double cost = residuals(e, v).squaredNorm();
      if (!best_ || cost < best_cost_) {
        best_ = std::make_shared<CurveEvaluation>(e);
        best_cost_ = cost;
      }
    }
    if (cache_.size() >= 4) cache_.erase(cache_.begin());
    cache_.emplace_back(u, std::move(e));
    return &cache_.back().second;
  }

  /// Forward differences in u: column j = (r(u + h e_j) − r(u)) / h, each perturbed curve warm started from the
  /// orbits at u (a parameter that enters only the residuals, phase_offset, needs no orbit).
  bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& jac) {
    const CurveEvaluation* base = evaluate(u);
    if (!base->ok) return false;
    const CurveEvaluation b = *base;  // the cache may move
    const ModelValues v0 = values(u);
    const Eigen::VectorXd r0 = residuals(b, v0);
    jac.resize(size(), count());
    const double h = options_.fd_step;
    for (long j = 0; j < count(); ++j) {
      Eigen::VectorXd uj = u;
      uj[j] += h;
      const ModelValues vj = values(uj);
      if (params_[static_cast<std::size_t>(j)].name == "phase_offset") {
        jac.col(j) = (residuals(b, vj) - r0) / h;
        continue;
      }
      CurveEvaluation e;
      try {
        e = model_.warm(vj, b, true);
      } catch (const InvalidParameter& ex) {
        e.ok = false;
        e.error = ex.what();
      } catch (const NumericalFailure& ex) {
        e.ok = false;
        e.error = ex.what();
      }
      if (!e.ok) {  // the step leaves the law's valid set: the backward difference
        uj[j] = u[j] - h;
        const ModelValues vb = values(uj);
        e = model_.warm(vb, b, true);
        if (!e.ok) return false;
        jac.col(j) = (r0 - residuals(e, vb)) / h;
        continue;
      }
      jac.col(j) = (residuals(e, vj) - r0) / h;
    }
    return true;
  }

  bool over_budget() const { return model_.curves() >= options_.max_evaluations; }
  long failed() const { return failed_; }
  const std::string& last_error() const { return last_error_; }

 private:
  const FitCurve& data_;
  FitSettings settings_;
  FitOptions options_;
  std::vector<FitParameterInfo> params_;
  double sigma_a_, sigma_p_;
  AmForwardModel model_;
  std::vector<std::pair<Eigen::VectorXd, CurveEvaluation>> cache_;
  std::shared_ptr<const CurveEvaluation> best_;
  double best_cost_ = 0.0;
  long failed_ = 0;
  std::string last_error_;
};

/// Eigen's functor interface over Problem. A trial the model cannot evaluate returns large residuals (the step is
/// rejected and shortened); the evaluation budget stops the solver (UserAsked).
struct Functor {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  Problem* problem;
  bool budget_hit = false;
  int inputs() const { return static_cast<int>(problem->count()); }
  int values() const { return static_cast<int>(problem->size()); }
  int operator()(const Eigen::VectorXd& u, Eigen::VectorXd& f) {
    if (problem->over_budget()) {
      budget_hit = true;
      return -1;
    }
    const CurveEvaluation* e = problem->evaluate(u);
    if (!e->ok) {
      f.setConstant(problem->size(), 1e10);
      return 0;
    }
    f = problem->residuals(*e, problem->values(u));
    return 0;
  }
  int df(const Eigen::VectorXd& u, Eigen::MatrixXd& jac) {
    if (problem->over_budget()) {
      budget_hit = true;
      return -1;
    }
    if (!problem->jacobian(u, jac)) {
      budget_hit = false;
      return -1;
    }
    return 0;
  }
};

}  // namespace

namespace {

/// The data sorted in the sweep's order.
FitCurve sorted_curve(const FitCurve& c, CurveDirection direction) {
  std::vector<std::size_t> idx(c.distance.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return direction == CurveDirection::approach ? c.distance[a] > c.distance[b] : c.distance[a] < c.distance[b];
  });
  FitCurve s;
  for (std::size_t i : idx) {
    s.distance.push_back(c.distance[i]);
    s.amplitude.push_back(c.amplitude[i]);
    if (!c.phase.empty()) s.phase.push_back(c.phase[i]);
  }
  return s;
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
  r.condition_number = inf;
  if (q > 0) {
    Eigen::MatrixXd scaled(q, q);  // unit diagonal: D⁻¹ H D⁻¹
    for (long a = 0; a < q; ++a)
      for (long b = 0; b < q; ++b) scaled(a, b) = h(live[a], live[b]) / (d[live[a]] * d[live[b]]);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(scaled);
    const Eigen::VectorXd lam = es.eigenvalues();  // ascending
    r.condition_number = lam[0] > 0.0 ? lam[q - 1] / lam[0] : inf;
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
            if (std::abs(es.eigenvectors()(a, k)) > 1e-6) cov_u(live[a], live[a]) = inf;
    }
  }
  r.standard_errors.assign(static_cast<std::size_t>(p), inf);
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

}  // namespace

AmPrediction predict_am_curve(const std::vector<double>& distance, const FitSettings& settings,
                              const FitOptions& options) {
  settings.validate();
  FitCurve c;
  c.distance = distance;
  c.amplitude.assign(distance.size(), 1.0);
  c.validate();
  const FitCurve s = sorted_curve(c, options.direction);
  const AmForwardModel model(settings, options, s.distance);
  ModelValues v;
  v.law = options.law_values;
  v.distance_offset = calibration_value(options, "distance_offset");
  v.amplitude_scale = calibration_value(options, "amplitude_scale");
  v.phase_offset = calibration_value(options, "phase_offset");
  const CurveEvaluation e = model.walk(v);
  if (!e.ok) throw NumericalFailure("forward model: " + e.error);
  AmPrediction out;
  out.amplitude.resize(distance.size());
  out.phase.resize(distance.size());
  out.contact.resize(distance.size());
  out.jumped.resize(distance.size());
  for (std::size_t i = 0; i < distance.size(); ++i) {
    const std::size_t k = static_cast<std::size_t>(
        std::find(s.distance.begin(), s.distance.end(), distance[i]) - s.distance.begin());
    out.amplitude[i] = e.amplitude[k] / v.amplitude_scale;
    out.phase[i] = wrap(e.phase[k] + v.phase_offset);
    out.contact[i] = e.contact[k];
    out.jumped[i] = e.jumped[k];
  }
  return out;
}

FitResult fit_am_curve(const FitCurve& curve, const FitSettings& settings, const FitOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  curve.validate();
  settings.validate();
  options.validate();
  FitResult r;
  r.parameters = fit_parameter_info(options);
  const FitCurve data = sorted_curve(curve, options.direction);
  const long n = static_cast<long>(data.distance.size());
  const long p = static_cast<long>(r.parameters.size());
  const long m = n * (data.phase.empty() ? 1 : 2);
  if (m <= p)
    throw InvalidParameter("parameters", fmt::format("{} parameters cannot be fitted to {} residuals: fewer "
                                                     "parameters or more points",
                                                     p, m));
  // weights: the given noise, else the data's scatter (floored: noise-free synthetic data)
  std::vector<double> a_norm(data.amplitude);
  for (double& a : a_norm) a /= settings.free_amplitude;
  r.noise_estimated_amplitude = options.amplitude_noise == 0.0;
  r.noise_estimated_phase = options.phase_noise == 0.0 && !data.phase.empty();
  r.amplitude_noise = r.noise_estimated_amplitude ? std::max(scatter(a_norm, false), 1e-9) : options.amplitude_noise;
  r.phase_noise = data.phase.empty()         ? nan
                  : r.noise_estimated_phase ? std::max(scatter(data.phase, true), 1e-9)
                                            : options.phase_noise;
  Problem problem(data, settings, options, r.parameters, r.amplitude_noise, data.phase.empty() ? 1.0 : r.phase_noise);

  Eigen::VectorXd u = Eigen::VectorXd::Zero(p);
  {  // the model must work at the initial values: its failure there is not the solver's
    const CurveEvaluation* e0 = problem.evaluate(u);
    if (!e0->ok) throw NumericalFailure("the forward model fails at the initial values: " + e0->error);
  }
  Functor functor{&problem};
  Eigen::LevenbergMarquardt<Functor> lm(functor);
  lm.parameters.ftol = options.tolerance;
  lm.parameters.xtol = options.tolerance;
  lm.parameters.maxfev = 100000;  // the budget is max_evaluations, counted in curves (Functor)
  // the trust region in u itself (each u is already a natural scale: an e-fold of a law parameter, 1 nm of offset,
  // 1 rad of phase): the first step is at most |Δu| = 1 (MINPACK's own scaling by the Jacobian's column norms lets
  // a weakly determined parameter leap by many decades)
  lm.useExternalScaling = true;
  lm.diag = Eigen::VectorXd::Ones(p);
  lm.parameters.factor = 1.0;
  const int status = lm.minimize(u);
  r.iterations = static_cast<int>(lm.iter);
  r.solver_status = solver_status_text(status);
  const bool converged = status >= 1 && status <= 4;
  r.status = converged ? FitStatus::ok : FitStatus::not_converged;
  if (functor.budget_hit)
    r.solver_status = fmt::format("evaluation budget spent (max_evaluations = {})", options.max_evaluations);
  else if (status == Eigen::LevenbergMarquardtSpace::UserAsked)
    r.solver_status = "the Jacobian could not be evaluated: " + problem.last_error();

  // the estimates and their statistics (the Jacobian once more at the estimates)
  const CurveEvaluation* best = problem.evaluate(u);
  if (!best->ok) throw NumericalFailure("the forward model fails at the estimates: " + best->error);
  const CurveEvaluation e = *best;
  const ModelValues v = problem.values(u);
  const Eigen::VectorXd res = problem.residuals(e, v);
  for (long j = 0; j < p; ++j) r.estimates.push_back(to_parameter(r.parameters[static_cast<std::size_t>(j)], u[j]));
  r.cost = res.squaredNorm();
  r.reduced_chi2 = r.cost / static_cast<double>(m - p);
  Eigen::MatrixXd jac;
  if (problem.jacobian(u, jac)) {
    statistics(jac, r.reduced_chi2, u, options, r);
  } else {
    r.standard_errors.assign(static_cast<std::size_t>(p), nan);
    r.correlation.assign(static_cast<std::size_t>(p), std::vector<double>(static_cast<std::size_t>(p), nan));
    r.identifiable.assign(static_cast<std::size_t>(p), false);
    r.warnings.push_back("the Jacobian at the estimates could not be evaluated: no standard errors (" +
                         problem.last_error() + ")");
  }
  r.distance = data.distance;
  r.amplitude = data.amplitude;
  r.phase = data.phase;
  double sa = 0.0, sp = 0.0;
  for (long i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    r.fitted_amplitude.push_back(e.amplitude[k] / v.amplitude_scale);
    r.fitted_phase.push_back(wrap(e.phase[k] + v.phase_offset));
    const double da = (data.amplitude[k] - r.fitted_amplitude[k]) / settings.free_amplitude;
    sa += da * da;
    if (!data.phase.empty()) {
      const double dp = wrap(data.phase[k] - r.fitted_phase[k]);
      sp += dp * dp;
    }
  }
  r.contact = e.contact;
  r.jumped = e.jumped;
  r.rms_amplitude = std::sqrt(sa / static_cast<double>(n));
  r.rms_phase = data.phase.empty() ? nan : std::sqrt(sp / static_cast<double>(n));
  r.law_values = v.law;
  {  // every law value the run used, defaults and followed keys included (SI)
    const impact::LawRegistry registry = impact::LawRegistry::builtin();
    impact::LawArguments args;
    for (const auto& [k, x] : v.law)
      for (const auto& d : registry.keys())
        if (d.key == k) args.values[k] = x / law_unit_to_si(d.unit);
    for (const std::string& key : registry.find(options.law).keys)
      for (const auto& d : registry.keys())
        if (d.key == key && (!d.only_if_given || args.given(key)))
          r.law_values[key] = args.real(d, registry.keys()) * law_unit_to_si(d.unit);
  }
  if (!std::all_of(e.periodic.begin(), e.periodic.end(), [](bool b) { return b; }))
    r.warnings.push_back("at some distances the response does not settle on a periodic orbit (one period of the "
                         "transient is compared with the data there)");
  r.curve_evaluations = problem.model().curves();
  r.orbit_evaluations = problem.model().orbits();
  r.failed_evaluations = problem.failed();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace afmkit::spectroscopy
