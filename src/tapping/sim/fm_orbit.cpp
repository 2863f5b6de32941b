// FM orbits: Newton on (x(0), ẋ(0), ω, Γ) for periodicity, drive 90° ahead of the deflection's first harmonic
// and first-harmonic amplitude A (include/afmkit/tapping/fm.hpp, docs/theory-tapping.md#fm-afm).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include <Eigen/LU>
#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "afmkit/tapping/fm.hpp"
#include "afmkit/tapping/observer.hpp"

namespace afmkit::tapping {

FmSetting::FmSetting(Cantilever cantilever_, impact::ForceLaw law_, double amplitude_)
    : cantilever(cantilever_), law(std::move(law_)), amplitude(validate::positive("amplitude", amplitude_)) {
  validate::require(std::isfinite(amplitude), "amplitude", amplitude, "finite");
}

double FmSetting::free_drive() const {
  const double wn = cantilever.natural_frequency;
  return 2.0 * cantilever.damping_ratio() * wn * wn * amplitude;  // |L(iω_n)| = 1/(2ξω_n²)
}

TappingModel FmSetting::model(double separation, double frequency, double drive) const {
  return TappingModel(cantilever, Drive(drive, frequency), law, separation);
}

FmState free_fm_state(const FmSetting& setting) {
  const double wn = setting.cantilever.natural_frequency;
  return {{0.0, setting.amplitude * wn}, wn, setting.free_drive()};
}

void FmOptions::validate() const {
  shooting.validate();
  validate::require(std::isfinite(difference_step) && difference_step >= 0.0 && difference_step <= 1e-2,
                    "difference_step", difference_step, "in [0, 1e-2]");
}

double FmOrbit::frequency_shift() const { return state.frequency - natural_frequency; }
double FmOrbit::drive_ratio() const { return state.drive / free_drive; }
// −∫ H ẋ dt: equal to W − viscous on an exact orbit, but free of the energy mismatch ~ A²·residual of a converged
// one (which W − viscous carries, Q times larger relative to the viscous loss)
double FmOrbit::tip_dissipation() const { return metrics.contact_dissipation; }

namespace {

/// Quadrature panel of the orbit integrals: a fraction of the shortest period present (as analyse_orbit).
double quadrature_panel(const TappingModel& model) {
  const double wn = model.cantilever.natural_frequency;
  double stiff = wn * wn;
  if (const auto* p = model.law.piecewise_linear()) stiff += std::max(p->approach_stiffness, p->departure_stiffness);
  const double shortest = std::min(model.period(), 2.0 * std::numbers::pi / std::sqrt(stiff));
  return shortest / 12.0 / (model.law.piecewise_linear() ? 1.0 : 4.0);
}

/// One period of the driven orbit from z = (x(0), ẋ(0), ω, Γ[, l]): the scaled residuals, the monodromy and the
/// orbit integrals.
struct Evaluation {
  Eigen::VectorXd residual;
  Eigen::Matrix3d sensitivity = Eigen::Matrix3d::Identity();  // ∂(x, ẋ, l)(T)/∂(x, ẋ, l)(0)
  OrbitMetrics metrics;
  double norm = 0.0;
  bool end_contact = false;  // the memory of a contact-aware law at the end of the period
};

/// The FM conditions at a fixed separation (4 unknowns) or at a fixed gap of the lower turning point (5 unknowns:
/// the separation too, with the condition min gap = target).
class FmProblem {
 public:
  FmProblem(const FmSetting& setting, double separation, std::optional<double> gap, const FmOptions& options)
      : setting_(setting), separation_(separation), gap_(gap), options_(options) {
    const double wn = setting.cantilever.natural_frequency, a = setting.amplitude;
    scale_.resize(size());
    scale_.head<4>() << a, a * wn, wn, setting.free_drive();
    if (gap_) scale_(4) = a;
    if (options.difference_step > 0) step_ = options.difference_step;
    else if (resolve_integrator(setting.model(separation, wn, scale_(3)), options.shooting.simulation.integrator) ==
             Integrator::adaptive)
      step_ = std::max(1e-7, std::sqrt(options.shooting.simulation.relative_tolerance));
    else step_ = 1e-7;
  }

  int size() const { return gap_ ? 5 : 4; }
  const Eigen::VectorXd& scale() const { return scale_; }
  long evaluations() const { return evaluations_; }
  double separation(const Eigen::VectorXd& z) const { return gap_ ? z(4) : separation_; }
  /// The memory of contact the period starts with (contact-aware laws, docs/force-laws.md#hysteresis).
  bool memory() const { return memory_; }
  void set_memory(bool contact) { memory_ = contact; }

  Evaluation evaluate(const Eigen::VectorXd& z, bool sensitivity) {
    ++evaluations_;
    const TappingModel model = setting_.model(separation(z), z(2), z(3));
    const double period = model.period();
    SimulationOptions o = options_.shooting.simulation;
    o.sensitivity = sensitivity;
    OrbitIntegrals integrals(quadrature_panel(model));
    const SimulationResult r = simulate(model, 0.0, {z(0), z(1), memory_}, period, o, &integrals);
    Evaluation e;
    const double a = setting_.amplitude;
    const std::complex<double> c1 = 2.0 * integrals.fourier[1] / period;  // x ≈ x̄ + Re(c1 e^{iωt}); want −iA
    e.residual.resize(size());
    e.residual.head<4>() << (r.state.position - z(0)) / scale_(0), (r.state.velocity - z(1)) / (a * z(2)),
        c1.real() / a, (-c1.imag() - a) / a;
    if (gap_) e.residual(4) = (integrals.min_gap - *gap_) / a;
    e.norm = e.residual.cwiseAbs().maxCoeff();
    e.sensitivity = r.sensitivity;
  e.end_contact = r.state.contact;
    OrbitMetrics& m = e.metrics;
    m.offset = integrals.fourier[0].real() / period;
    m.amplitude = std::abs(c1);
    m.phase = -std::arg(c1);
    for (int k = 2; k <= 5; ++k) m.harmonics[k - 2] = 2.0 * std::abs(integrals.fourier[k]) / period;
    m.contact_fraction = integrals.contact_time / period;
    m.peak_force = integrals.peak_force;
    m.min_gap = integrals.min_gap;
    m.drive_work = integrals.drive_work;
    m.viscous_dissipation = integrals.viscous_dissipation;
    m.contact_dissipation = integrals.contact_dissipation;
    m.impacts_per_period_multiple = r.stats.impacts;
    m.sticking_duration = r.stats.sticking_duration;
    m.duration = period;
    return e;
  }

  /// Jacobian of the scaled residuals with respect to the scaled unknowns u = z / scale: forward differences,
  /// with the periodicity rows exact.
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& z, const Evaluation& at) {
    const int n = size();
    Eigen::MatrixXd j(n, n);
    for (int c = 0; c < n; ++c) {
      Eigen::VectorXd zc = z;
      zc(c) += step_ * scale_(c);
      j.col(c) = (evaluate(zc, false).residual - at.residual) / step_;
    }
    set_exact_rows(j, z, at);
    return j;
  }

  /// The periodicity rows' columns x(0), ẋ(0) (and l) from the exact sensitivity (variational equations +
  /// saltation matrices) of the evaluation at z.
  void set_exact_rows(Eigen::MatrixXd& j, const Eigen::VectorXd& z, const Evaluation& at) const {
    const double a = setting_.amplitude;
    const Eigen::Matrix3d& s = at.sensitivity;
    const double row_scale[2] = {scale_(0), a * z(2)};
    for (int r = 0; r < 2; ++r) {
      j(r, 0) = (s(r, 0) - (r == 0 ? 1.0 : 0.0)) * scale_(0) / row_scale[r];
      j(r, 1) = (s(r, 1) - (r == 1 ? 1.0 : 0.0)) * scale_(1) / row_scale[r];
      if (gap_) j(r, 4) = s(r, 2) * scale_(4) / row_scale[r];
    }
  }

 private:
  const FmSetting& setting_;
  double separation_;
  std::optional<double> gap_;
  const FmOptions& options_;
  Eigen::VectorXd scale_;
  double step_ = 1e-7;
  long evaluations_ = 0;
  bool memory_ = false;
};

std::optional<FmOrbit> solve(const FmSetting& setting, double separation, std::optional<double> gap,
                             const FmState& guess, const FmOptions& options, FmJacobian* reuse) {
  options.validate();
  validate::finite("separation", separation);
  if (gap) validate::finite("min_gap", *gap);
  validate::finite("position", guess.initial.position);
  validate::finite("velocity", guess.initial.velocity);
  validate::positive("frequency", guess.frequency);
  validate::positive("drive", guess.drive);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  FmProblem problem(setting, separation, gap, options);
  const TappingModel probe = setting.model(separation, guess.frequency, guess.drive);
  // the adaptive integrator's map is only as smooth as its tolerance: do not ask Newton for more (as shooting)
  const double tolerance =
      resolve_integrator(probe, options.shooting.simulation.integrator) == Integrator::adaptive
          ? std::max(options.shooting.tolerance, 10.0 * options.shooting.simulation.relative_tolerance)
          : options.shooting.tolerance;
  // the memory of a contact-aware law is part of the orbit (as in shooting): Newton runs with the guess's memory,
  // and a converged state whose period ends with the other memory continues with that one (at most twice)
  problem.set_memory(guess.initial.contact);
  int memory_switches = 0;
  Eigen::VectorXd z(problem.size());
  z.head<4>() << guess.initial.position, guess.initial.velocity, guess.frequency, guess.drive;
  if (gap) z(4) = separation;
  Evaluation e = problem.evaluate(z, true);
  // the Jacobian: a previous solve's (Broyden-updated along the iterations) or forward differences here
  Eigen::MatrixXd j;
  bool fresh = !(reuse && reuse->matrix.rows() == problem.size());
  bool refresh = fresh;
  for (int it = 0;; ++it) {
    if (e.norm <= tolerance && e.end_contact != problem.memory()) {
      if (memory_switches == 2) return std::nullopt;  // the memory does not repeat: no periodic orbit here
      ++memory_switches;
      problem.set_memory(e.end_contact);
      e = problem.evaluate(z, true);
    }
    if (e.norm <= tolerance && e.end_contact == problem.memory()) {
      if (reuse && j.size() > 0) reuse->matrix = j;
      FmOrbit orbit;
      orbit.separation = problem.separation(z);
      orbit.state = {{z(0), z(1), problem.memory()}, z(2), z(3)};
      orbit.natural_frequency = setting.cantilever.natural_frequency;
      orbit.free_drive = setting.free_drive();
      orbit.monodromy = e.sensitivity.topLeftCorner<2, 2>();
      PeriodicOrbit p;  // Floquet multipliers of the monodromy (frozen drive)
      p.monodromy = orbit.monodromy;
      set_floquet(p);
      orbit.floquet_multipliers = p.floquet_multipliers;
      orbit.floquet_max = p.floquet_max;
      orbit.stable = p.stable;
      orbit.residual = e.norm;
      orbit.iterations = it;
      orbit.evaluations = problem.evaluations();
      orbit.metrics = e.metrics;
      return orbit;
    }
    if (it >= options.shooting.max_iterations) return std::nullopt;
    if (elapsed() > options.shooting.time_budget_seconds)
      throw NumericalFailure(fmt::format("FM orbit: time budget of {} s exhausted after {} Newton iterations "
                                         "(residual {:.3g}) at separation {}",
                                         options.shooting.time_budget_seconds, it, e.norm, problem.separation(z)));
    if (refresh) {
      j = problem.jacobian(z, e);
      fresh = true;
      refresh = false;
    } else {
      if (j.size() == 0) j = reuse->matrix;
      problem.set_exact_rows(j, z, e);
    }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(j);
    Eigen::VectorXd step;
    if (lu.isInvertible()) step = -lu.solve(e.residual).cwiseProduct(problem.scale());
    if (step.size() == 0 || !step.allFinite()) {
      if (fresh) return std::nullopt;
      refresh = true;  // the reused Jacobian is singular here: differences
      continue;
    }
    // keep ω and Γ positive, the frequency step moderate and (gap condition) the separation step below A
    double lambda = 1.0;
    if (std::abs(step(2)) > 0.2 * z(2)) lambda = 0.2 * z(2) / std::abs(step(2));
    if (z(3) + lambda * step(3) < 0.2 * z(3)) lambda = 0.8 * z(3) / std::abs(step(3));
    if (gap && std::abs(lambda * step(4)) > setting.amplitude) lambda = setting.amplitude / std::abs(step(4));
    bool accepted = false;
    const int trials = fresh ? 10 : 2;  // a reused Jacobian that does not reduce the residual is recomputed
    for (int k = 0; k < trials; ++k, lambda *= 0.5) {
      const Eigen::VectorXd trial = z + lambda * step;
      Evaluation t = problem.evaluate(trial, true);
      if (t.norm < e.norm || (fresh && k == trials - 1)) {
        accepted = t.norm < e.norm;
        if (accepted) {
          // Broyden's update of the difference columns (the periodicity rows are set exactly next iteration)
          const Eigen::VectorXd du = (lambda * step).cwiseQuotient(problem.scale());
          const Eigen::VectorXd dr = t.residual - e.residual;
          if (du.squaredNorm() > 0) j += (dr - j * du) * du.transpose() / du.squaredNorm();
          if (!fresh && t.norm > 0.5 * e.norm) refresh = true;  // slow progress: differences next
          fresh = false;
        }
        z = trial;
        e = std::move(t);
        break;
      }
    }
    if (!accepted) {
      if (!fresh) {  // the kept Jacobian misled the step (z unchanged): differences here
        refresh = true;
        continue;
      }
      // a fresh Jacobian and no decrease: z moved by the smallest trial step (as shooting); differences there
      if (e.norm > 1e3 * tolerance) return std::nullopt;
      refresh = true;
    }
  }
}

}  // namespace

std::optional<FmOrbit> try_solve_fm(const FmSetting& setting, double separation, const FmState& guess,
                                    const FmOptions& options, FmJacobian* reuse) {
  return solve(setting, separation, std::nullopt, guess, options, reuse);
}

std::optional<FmOrbit> try_solve_fm_at_gap(const FmSetting& setting, double min_gap, double separation_guess,
                                           const FmState& guess, const FmOptions& options, FmJacobian* reuse) {
  return solve(setting, separation_guess, min_gap, guess, options, reuse);
}

const char* fm_status_name(FmStatus status) {
  switch (status) {
    case FmStatus::converged: return "ok";
    case FmStatus::no_orbit: return "no_orbit";
  }
  return "?";
}

}  // namespace afmkit::tapping
