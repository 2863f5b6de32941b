// FM orbits: Newton on (x(0), ẋ(0), ω, Γ) for periodicity, drive 90° ahead of the deflection's first harmonic
// and first-harmonic amplitude A (include/afmkit/tapping/fm.hpp, docs/theory-tapping.md#fm-afm).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

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

/// One period of the driven orbit from z = (x(0), ẋ(0), ω, Γ): the four scaled residuals, the monodromy and the
/// orbit integrals.
struct Evaluation {
  Eigen::Vector4d residual = Eigen::Vector4d::Zero();
  Eigen::Matrix2d monodromy = Eigen::Matrix2d::Identity();
  OrbitMetrics metrics;
  double norm = 0.0;
};

class FmProblem {
 public:
  FmProblem(const FmSetting& setting, double separation, const FmOptions& options)
      : setting_(setting), separation_(separation), options_(options) {
    const double wn = setting.cantilever.natural_frequency, a = setting.amplitude;
    scale_ << a, a * wn, wn, setting.free_drive();
    if (options.difference_step > 0) step_ = options.difference_step;
    else if (resolve_integrator(setting.model(separation, wn, scale_(3)), options.shooting.simulation.integrator) ==
             Integrator::adaptive)
      step_ = std::max(1e-7, std::sqrt(options.shooting.simulation.relative_tolerance));
    else step_ = 1e-7;
  }

  const Eigen::Vector4d& scale() const { return scale_; }
  long evaluations() const { return evaluations_; }

  Evaluation evaluate(const Eigen::Vector4d& z, bool sensitivity, bool metrics) {
    ++evaluations_;
    const TappingModel model = setting_.model(separation_, z(2), z(3));
    const double period = model.period();
    SimulationOptions o = options_.shooting.simulation;
    o.sensitivity = sensitivity;
    OrbitIntegrals integrals(quadrature_panel(model));
    const SimulationResult r = simulate(model, 0.0, {z(0), z(1)}, period, o, &integrals);
    Evaluation e;
    const double a = setting_.amplitude;
    const std::complex<double> c1 = 2.0 * integrals.fourier[1] / period;  // x ≈ x̄ + Re(c1 e^{iωt}); want −iA
    e.residual << (r.state.position - z(0)) / scale_(0), (r.state.velocity - z(1)) / (a * z(2)), c1.real() / a,
        (-c1.imag() - a) / a;
    e.norm = e.residual.cwiseAbs().maxCoeff();
    e.monodromy = r.sensitivity.topLeftCorner<2, 2>();
    if (metrics) {
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
    }
    return e;
  }

  /// Jacobian of the scaled residuals with respect to the scaled unknowns u = z / scale.
  Eigen::Matrix4d jacobian(const Eigen::Vector4d& z, const Evaluation& at) {
    Eigen::Matrix4d j;
    for (int c = 0; c < 4; ++c) {
      Eigen::Vector4d zc = z;
      const double h = step_ * scale_(c);
      zc(c) += h;
      j.col(c) = (evaluate(zc, false, false).residual - at.residual) / step_;
    }
    // periodicity block from the exact monodromy (variational equations + saltation matrices)
    const double a = setting_.amplitude;
    const Eigen::Matrix2d mi = at.monodromy - Eigen::Matrix2d::Identity();
    j(0, 0) = mi(0, 0);
    j(0, 1) = mi(0, 1) * scale_(1) / scale_(0);
    j(1, 0) = mi(1, 0) * scale_(0) / (a * z(2));
    j(1, 1) = mi(1, 1) * scale_(1) / (a * z(2));
    return j;
  }

 private:
  const FmSetting& setting_;
  double separation_;
  const FmOptions& options_;
  Eigen::Vector4d scale_;
  double step_ = 1e-7;
  long evaluations_ = 0;
};

}  // namespace

std::optional<FmOrbit> try_solve_fm(const FmSetting& setting, double separation, const FmState& guess,
                                    const FmOptions& options) {
  options.validate();
  validate::finite("separation", separation);
  validate::finite("position", guess.initial.position);
  validate::finite("velocity", guess.initial.velocity);
  validate::positive("frequency", guess.frequency);
  validate::positive("drive", guess.drive);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  FmProblem problem(setting, separation, options);
  const TappingModel probe = setting.model(separation, guess.frequency, guess.drive);
  // the adaptive integrator's map is only as smooth as its tolerance: do not ask Newton for more (as shooting)
  const double tolerance =
      resolve_integrator(probe, options.shooting.simulation.integrator) == Integrator::adaptive
          ? std::max(options.shooting.tolerance, 10.0 * options.shooting.simulation.relative_tolerance)
          : options.shooting.tolerance;
  Eigen::Vector4d z(guess.initial.position, guess.initial.velocity, guess.frequency, guess.drive);
  Evaluation e = problem.evaluate(z, true, true);
  for (int it = 0;; ++it) {
    if (e.norm <= tolerance) {
      FmOrbit orbit;
      orbit.separation = separation;
      orbit.state = {{z(0), z(1)}, z(2), z(3)};
      orbit.natural_frequency = setting.cantilever.natural_frequency;
      orbit.free_drive = setting.free_drive();
      orbit.monodromy = e.monodromy;
      PeriodicOrbit p;  // Floquet multipliers of the monodromy (frozen drive)
      p.monodromy = e.monodromy;
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
                                         options.shooting.time_budget_seconds, it, e.norm, separation));
    const Eigen::Matrix4d j = problem.jacobian(z, e);
    const Eigen::FullPivLU<Eigen::Matrix4d> lu(j);
    if (!lu.isInvertible()) return std::nullopt;
    Eigen::Vector4d step = -lu.solve(e.residual).cwiseProduct(problem.scale());
    if (!step.allFinite()) return std::nullopt;
    // keep ω and Γ positive and the frequency step moderate
    double lambda = 1.0;
    if (std::abs(step(2)) > 0.2 * z(2)) lambda = 0.2 * z(2) / std::abs(step(2));
    if (z(3) + lambda * step(3) < 0.2 * z(3)) lambda = 0.8 * z(3) / std::abs(step(3));
    bool accepted = false;
    for (int k = 0; k < 10; ++k, lambda *= 0.5) {
      const Eigen::Vector4d trial = z + lambda * step;
      Evaluation t = problem.evaluate(trial, true, true);
      if (t.norm < e.norm || k == 9) {
        accepted = t.norm < e.norm;
        z = trial;
        e = std::move(t);
        break;
      }
    }
    if (!accepted && e.norm > 1e3 * tolerance) return std::nullopt;
  }
}

const char* fm_status_name(FmStatus status) {
  switch (status) {
    case FmStatus::converged: return "ok";
    case FmStatus::no_orbit: return "no_orbit";
  }
  return "?";
}

}  // namespace afmkit::tapping
