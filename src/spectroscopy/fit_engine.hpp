#pragma once
// The least-squares engine shared by the AM and the FM fit (docs/fitting.md#solver): the problem u -> weighted
// residuals over a forward model (cached evaluations, warm starts from the best one, Huber's loss, the Jacobian by
// forward differences), Eigen's Levenberg–Marquardt over it, and the statistics at the estimates. What differs
// between the fits — the forward model and the residuals of the data — comes in as the Model type and a function.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/NonLinearOptimization>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/fit.hpp"
#include "afmkit/spectroscopy/fit_model.hpp"

namespace afmkit::spectroscopy::engine {

/// x wrapped to (−π, π].
double wrap(double x);
/// The data's noise about a smooth curve: 1.4826 · median |second difference| / √6 (angle: differences wrapped).
double scatter(const std::vector<double>& y, bool angle);
/// Eigen's LevenbergMarquardtSpace::Status in words.
std::string solver_status_text(int status);
/// Covariance, correlations and identifiability from the weighted Jacobian J (in u) at the estimates (fills
/// standard_errors, correlation, identifiable, condition_number, warnings of `r`; r.parameters and r.estimates set).
void statistics(const Eigen::MatrixXd& jac, double s2, const Eigen::VectorXd& u, const FitOptions& options,
                FitResult& r);
/// The indices of the points in the sweep's order (approach: distance decreasing; retract: increasing).
std::vector<std::size_t> sweep_order(const std::vector<double>& distance, CurveDirection direction);
/// values[order[k]] for each k (empty for empty values).
std::vector<double> in_order(const std::vector<double>& values, const std::vector<std::size_t>& order);
/// Every law value a run used (registry keys, SI): `law` and the registry's defaults and followed keys.
std::map<std::string, double> law_values_used(const std::string& law_name, const std::map<std::string, double>& law);

/// The problem as the solver sees it: u -> weighted residuals. Model: AmForwardModel or FmForwardModel (walk, warm,
/// curves, Evaluation with ok and error). `raw` gives the weighted residuals (before Huber's loss) of an evaluation.
template <class Model>
class Problem {
 public:
  using Evaluation = typename Model::Evaluation;
  using Residuals = std::function<Eigen::VectorXd(const Evaluation&, const ModelValues&)>;

  Problem(const Model& model, const FitOptions& options, std::vector<FitParameterInfo> params, long size,
          Residuals raw)
      : model_(model), options_(options), params_(std::move(params)), size_(size), raw_(std::move(raw)) {}

  long size() const { return size_; }
  long count() const { return static_cast<long>(params_.size()); }
  const Model& model() const { return model_; }

  ModelValues values(const Eigen::VectorXd& u) const {
    ModelValues v = ModelValues::of(options_);
    for (std::size_t j = 0; j < params_.size(); ++j)
      v.set(params_[j].name, to_parameter(params_[j], u[static_cast<long>(j)]));
    return v;
  }

  Eigen::VectorXd residuals(const Evaluation& e, const ModelValues& v) const {
    Eigen::VectorXd r = raw_(e, v);
    for (long i = 0; i < r.size(); ++i) r[i] = robust(r[i]);
    return r;
  }

  /// Huber's loss as a residual: r for |r| ≤ c, sign(r)·√(2c|r| − c²) beyond (Σ r'² is Huber's cost), c =
  /// options.huber noise units; 0: plain least squares. A point the model puts on another branch than the data
  /// (next to a jump, hundreds of σ off) then pulls linearly, not quadratically.
  double robust(double x) const {
    const double c = options_.huber;
    if (c <= 0.0 || std::abs(x) <= c) return x;
    return std::copysign(std::sqrt(2.0 * c * std::abs(x) - c * c), x);
  }

  /// The evaluation at u (cached: the solver asks for the Jacobian where it evaluated the residuals).
  const Evaluation* evaluate(const Eigen::VectorXd& u) {
    for (const auto& [x, e] : cache_)
      if (x.size() == u.size() && x == u) return &e;
    const ModelValues v = values(u);
    // warm started from the best evaluation so far (the solver's current point), else the whole sweep
    Evaluation e = guarded([&] { return best_ ? model_.warm(v, *best_) : model_.walk(v); });
    if (!e.ok) {
      ++failed_;
      last_error_ = e.error;
    } else {
      const double cost = residuals(e, v).squaredNorm();
      if (!best_ || cost < best_cost_) {
        best_ = std::make_shared<Evaluation>(e);
        best_cost_ = cost;
      }
    }
    if (cache_.size() >= 4) cache_.erase(cache_.begin());
    cache_.emplace_back(u, std::move(e));
    return &cache_.back().second;
  }

  /// Forward differences in u: column j = (r(u + h e_j) − r(u)) / h, each perturbed curve warm started from the
  /// orbits at u (a parameter that enters only the residuals needs no orbit); backward where the forward step
  /// leaves the law's valid set.
  bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& jac) {
    const Evaluation* base = evaluate(u);
    if (!base->ok) return false;
    const Evaluation b = *base;  // the cache may move
    const Eigen::VectorXd r0 = residuals(b, values(u));
    jac.resize(size(), count());
    const double h = options_.fd_step;
    for (long j = 0; j < count(); ++j) {
      Eigen::VectorXd uj = u;
      uj[j] += h;
      const ModelValues vj = values(uj);
      if (residual_only(params_[static_cast<std::size_t>(j)].name)) {
        jac.col(j) = (residuals(b, vj) - r0) / h;
        continue;
      }
      Evaluation e = guarded([&] { return model_.warm(vj, b, true); });
      if (!e.ok) {  // the step leaves the law's valid set: the backward difference
        uj[j] = u[j] - h;
        const ModelValues vb = values(uj);
        e = guarded([&] { return model_.warm(vb, b, true); });
        if (!e.ok) {
          last_error_ = e.error;
          return false;
        }
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
  const Model& model_;
  const FitOptions& options_;
  std::vector<FitParameterInfo> params_;
  long size_;
  Residuals raw_;
  std::vector<std::pair<Eigen::VectorXd, Evaluation>> cache_;
  std::shared_ptr<const Evaluation> best_;
  double best_cost_ = 0.0;
  long failed_ = 0;
  std::string last_error_;

  /// A trial outside a law's valid set (InvalidParameter, e.g. energy gain) or where the orbits fail
  /// (NumericalFailure) is an evaluation that is not ok.
  template <class F>
  static Evaluation guarded(F&& f) {
    try {
      return f();
    } catch (const InvalidParameter& ex) {
      Evaluation e;
      e.error = ex.what();
      return e;
    } catch (const NumericalFailure& ex) {
      Evaluation e;
      e.error = ex.what();
      return e;
    }
  }
};

/// Eigen's functor interface over a Problem. A trial the model cannot evaluate returns large residuals (the step is
/// rejected and shortened); the evaluation budget stops the solver (UserAsked).
template <class P>
struct Functor {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  P* problem;
  bool budget_hit = false;
  int inputs() const { return static_cast<int>(problem->count()); }
  int values() const { return static_cast<int>(problem->size()); }
  int operator()(const Eigen::VectorXd& u, Eigen::VectorXd& f) {
    if (problem->over_budget()) {
      budget_hit = true;
      return -1;
    }
    const auto* e = problem->evaluate(u);
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

/// The LM solve from u = 0 (the initial values) and the statistics at the estimates: fills status, solver_status,
/// iterations, estimates, cost, reduced_chi2, standard errors, correlation, identifiability, evaluation counts and
/// the law values of `r` (r.parameters set); returns the evaluation at the estimates and their values. Bad input
/// is the caller's to refuse before; the model failing at the initial values or at the estimates is a
/// NumericalFailure.
template <class Model>
std::pair<typename Model::Evaluation, ModelValues> solve(Problem<Model>& problem, const FitOptions& options,
                                                         FitResult& r) {
  const long p = problem.count(), m = problem.size();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(p);
  {  // the model must work at the initial values: its failure there is not the solver's
    const auto* e0 = problem.evaluate(u);
    if (!e0->ok) throw NumericalFailure("the forward model fails at the initial values: " + e0->error);
  }
  Functor<Problem<Model>> functor{&problem};
  Eigen::LevenbergMarquardt<Functor<Problem<Model>>> lm(functor);
  lm.parameters.ftol = options.tolerance;
  lm.parameters.xtol = options.tolerance;
  lm.parameters.maxfev = 100000;  // the budget is max_evaluations, counted in curves (Functor)
  // the trust region in u itself (each u is already a natural scale: an e-fold of a law parameter, 1 nm of offset,
  // 1 rad of phase, 1 Hz of frequency shift): the first step is at most |Δu| = 1 (MINPACK's own scaling by the
  // Jacobian's column norms lets a weakly determined parameter leap by many decades)
  lm.useExternalScaling = true;
  lm.diag = Eigen::VectorXd::Ones(p);
  lm.parameters.factor = 1.0;
  const int status = lm.minimize(u);
  r.iterations = static_cast<int>(lm.iter);
  r.solver_status = solver_status_text(status);
  const bool converged = status >= 1 && status <= 4;
  r.status = converged ? FitStatus::ok : FitStatus::not_converged;
  if (functor.budget_hit)
    r.solver_status = "evaluation budget spent (max_evaluations = " + std::to_string(options.max_evaluations) + ")";
  else if (status == Eigen::LevenbergMarquardtSpace::UserAsked)
    r.solver_status = "the Jacobian could not be evaluated: " + problem.last_error();

  // the estimates and their statistics (the Jacobian once more at the estimates)
  const auto* best = problem.evaluate(u);
  if (!best->ok) throw NumericalFailure("the forward model fails at the estimates: " + best->error);
  const typename Model::Evaluation e = *best;
  const ModelValues v = problem.values(u);
  const Eigen::VectorXd res = problem.residuals(e, v);
  for (long j = 0; j < p; ++j) r.estimates.push_back(to_parameter(r.parameters[static_cast<std::size_t>(j)], u[j]));
  r.cost = res.squaredNorm();
  r.reduced_chi2 = r.cost / static_cast<double>(m - p);
  Eigen::MatrixXd jac;
  if (problem.jacobian(u, jac)) {
    statistics(jac, r.reduced_chi2, u, options, r);
  } else {
    const auto np = static_cast<std::size_t>(p);
    r.standard_errors.assign(np, std::numeric_limits<double>::quiet_NaN());
    r.correlation.assign(np, std::vector<double>(np, std::numeric_limits<double>::quiet_NaN()));
    r.identifiable.assign(np, false);
    r.warnings.push_back("the Jacobian at the estimates could not be evaluated: no standard errors (" +
                         problem.last_error() + ")");
  }
  r.law_values = law_values_used(options.law, v.law);
  r.curve_evaluations = problem.model().curves();
  r.orbit_evaluations = problem.model().orbits();
  r.failed_evaluations = problem.failed();
  return {e, v};
}

/// The weights' σ: the given one, else the data's scatter floored at `floor` (noise-free synthetic data).
inline double noise(double given, const std::vector<double>& y, bool angle, double floor, bool& estimated) {
  estimated = given == 0.0;
  return estimated ? std::max(scatter(y, angle), floor) : given;
}

}  // namespace afmkit::spectroscopy::engine
