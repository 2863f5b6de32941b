#include "afmkit/impact/impact.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/numbers.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/core/validate.hpp"
#include "impact_detail.hpp"

namespace afmkit::impact {

namespace {
using afmkit::numbers::nan;

Body validated(const Body& b, const char* index) {
  const std::string i(index);
  return {validate::positive("mass" + i, b.mass), validate::finite("position" + i, b.position),
          validate::finite("velocity" + i, b.velocity)};
}
}  // namespace

ImpactProblem::ImpactProblem(Body body1, Body body2, ForceLaw law, ExternalForces external)
    : body1_(validated(body1, "1")), body2_(validated(body2, "2")), law_(std::move(law)), external_(std::move(external)) {
  validate::finite("force1", external_.on_body1);
  validate::finite("force2", external_.on_body2);
  const double rate = initial_gap_rate();
  // ḋ(t_s) < 0: the impact starts with an approach (seed-1 §II); e (eq. 2) needs ḋ(t_s) ≠ 0.
  validate::require(std::isfinite(rate) && rate < 0, "relative_velocity", rate,
                    "< 0 (v2 - v1: the bodies must approach each other at the start of the impact)");
  // Scales must stay inside the double range (every later quantity is built from them).
  constexpr double tiny = std::numeric_limits<double>::min();
  const double total = total_mass(), mu = reduced_mass();
  validate::require(std::isfinite(total), "mass1", body1_.mass,
                    fmt::format("such that mass1 + mass2 is finite (mass2 = {}); rescale the mass unit", body2_.mass));
  validate::require(mu >= tiny, "mass1", body1_.mass,
                    fmt::format("such that the reduced mass m1 m2/(m1 + m2) >= {:g} (mass2 = {}); rescale the mass unit",
                                tiny, body2_.mass));
  const double kinetic = 0.5 * mu * rate * rate;
  validate::require(std::isfinite(kinetic) && kinetic >= tiny && std::isfinite(body1_.mass * body1_.velocity) &&
                        std::isfinite(body2_.mass * body2_.velocity),
                    "relative_velocity", rate,
                    fmt::format("such that the momenta and the relative kinetic energy ½ μ (v2 - v1)² (μ = {}) lie in "
                                "[{:g}, {:g}]; rescale the units",
                                mu, tiny, std::numeric_limits<double>::max()));
  law_.require_dissipative();  // K_b <= K_a etc. unless the law opts in (seed-1 eq. 6: loss = area >= 0)
}

ImpactProblem ImpactProblem::head_on(double mass1, double mass2, double approach_speed, double gap, ForceLaw law) {
  validate::positive("mass1", mass1);
  validate::positive("mass2", mass2);
  validate::require(std::isfinite(mass1 + mass2), "mass1", mass1,
                    fmt::format("such that mass1 + mass2 is finite (mass2 = {}); rescale the mass unit", mass2));
  validate::positive("approach_speed", approach_speed);
  validate::finite("gap", gap);
  const double total = mass1 + mass2;
  // centre of mass at rest at the origin
  Body b1{mass1, -mass2 / total * gap, mass2 / total * approach_speed};
  Body b2{mass2, mass1 / total * gap, -mass1 / total * approach_speed};
  return {b1, b2, std::move(law)};
}

const char* to_string(ImpactOutcome outcome) {
  return outcome == ImpactOutcome::separated ? "separated" : "captured";
}

double restitution_energy_loss(double m1, double m2, double relative_velocity, double e) {
  validate::positive("mass1", m1);
  validate::positive("mass2", m2);
  validate::finite("relative_velocity", relative_velocity);
  validate::non_negative("restitution", e);
  // eq. (3); (1 − e)(1 + e) rather than 1 − e², exact factor 1 − e for e near 1
  return (1.0 - e) * (1.0 + e) * (m1 * (m2 / (m1 + m2))) / 2.0 * relative_velocity * relative_velocity;
}

namespace detail {

double contact_gap_of(const ForceLaw& law) { return law.contact_gap(); }

SampleClock::SampleClock(double end_time, long points, std::vector<double> events)
    : end_time_(end_time), points_(points) {
  if (points_ <= 0) return;
  for (double e : events)
    if (e >= 0 && e <= end_time) events_.push_back(e);
  std::sort(events_.begin(), events_.end());
  advance();
}

double SampleClock::uniform(long k) const {
  return k + 1 == points_ ? end_time_ : end_time_ * static_cast<double>(k) / static_cast<double>(points_ - 1);
}

void SampleClock::advance() {
  for (;;) {
    const bool u = k_ < points_, e = j_ < events_.size();
    if (!u && !e) {
      has_next_ = false;
      return;
    }
    double t = 0;
    if (u && (!e || uniform(k_) <= events_[j_])) t = uniform(k_++);
    else t = events_[j_++];
    if (have_last_ && t == last_) continue;  // exact duplicate
    next_ = last_ = t;
    have_last_ = has_next_ = true;
    return;
  }
}

void SampleClock::pop() { advance(); }

void complete_result(const ImpactProblem& problem, ImpactResult& r, double relative_loss) {
  const double m1 = problem.body1().mass, m2 = problem.body2().mass, total = m1 + m2;
  const double mu = problem.reduced_mass();
  r.reduced_mass = mu;
  r.start_time = 0.0;
  r.reference_gap = problem.initial_gap();
  r.approach_gap_rate = problem.initial_gap_rate();
  r.contact_gap = contact_gap_of(problem.law());
  r.max_penetration = std::isnan(r.contact_gap) ? nan : r.contact_gap - r.minimum_gap;
  if (std::isnan(r.contact_gap)) {  // no contact edge: the whole impact interval counts as contact
    r.contact = true;
    r.contact_start = 0.0;
    r.contact_end = r.outcome == ImpactOutcome::separated ? r.end_time : nan;
  }
  if (!r.contact) r.contact_start = r.contact_end = nan;
  r.contact_duration = r.contact ? (std::isnan(r.contact_end) ? r.end_time : r.contact_end) - r.contact_start : 0.0;

  // Kinetic energy = centre-of-mass part + relative part ½ μ ḋ² (exact identity, avoids cancellation).
  auto kinetic = [&](const Body& b1, const Body& b2) {
    const double com = (m1 * b1.velocity + m2 * b2.velocity) / total, rel = b2.velocity - b1.velocity;
    return 0.5 * total * com * com + 0.5 * mu * rel * rel;
  };
  const Body& s1 = problem.body1();
  const Body& s2 = problem.body2();
  r.kinetic_energy_before = kinetic(s1, s2);
  r.kinetic_energy_after = kinetic(r.body1_after, r.body2_after);
  if (r.outcome == ImpactOutcome::separated) {
    const double com_s = (m1 * s1.velocity + m2 * s2.velocity) / total;
    const double com_f = (m1 * r.body1_after.velocity + m2 * r.body2_after.velocity) / total;
    const double rel_s = r.approach_gap_rate, rel_f = r.body2_after.velocity - r.body1_after.velocity;
    const double relative_ke = 0.5 * mu * rel_s * rel_s;
    r.departure_gap_rate = rel_f;
    r.restitution = -rel_f / rel_s;  // eq. (2)
    double rel_loss = 0.5 * mu * (rel_s - rel_f) * (rel_s + rel_f);
    r.restitution_deficit = (rel_s + rel_f) / rel_s;  // 1 − e, as accurate as the state (integrator)
    if (std::isfinite(relative_loss)) {
      // 1 − e² = x = loss/(½ μ ḋ(t_s)²) known to relative accuracy: 1 − e = x/(1 + e) without cancellation
      rel_loss = relative_loss;
      r.restitution_deficit = relative_loss / relative_ke / (1.0 + r.restitution);
    }
    r.kinetic_energy_loss = 0.5 * total * (com_s - com_f) * (com_s + com_f) + rel_loss;
    r.energy_loss_restitution = r.restitution_deficit * (1.0 + r.restitution) * relative_ke;  // eq. (3)
    r.energy_loss_area = hysteresis_energy_loss(problem.law(), r.minimum_gap, r.reference_gap);  // eq. (6)
  } else {
    r.departure_gap_rate = r.restitution = r.restitution_deficit = nan;
    r.kinetic_energy_loss = r.energy_loss_restitution = r.energy_loss_area = nan;
  }
}

}  // namespace detail

namespace {

/// The solved impact must be representable: non-finite times, gaps or speeds mean the input scales
/// (gap / speed, stiffness / reduced mass, …) leave the double range.
void require_finite_result(const ImpactResult& r) {
  const bool separated = r.outcome == ImpactOutcome::separated;
  for (auto [name, value] : {std::pair{"end_time", r.end_time}, std::pair{"minimum_time", r.minimum_time},
                             std::pair{"minimum_gap", r.minimum_gap},
                             std::pair{"kinetic_energy_before", r.kinetic_energy_before},
                             std::pair{"restitution", separated ? r.restitution : 0.0},
                             std::pair{"kinetic_energy_loss", separated ? r.kinetic_energy_loss : 0.0},
                             std::pair{"energy_loss_area", separated ? r.energy_loss_area : 0.0},
                             std::pair{"peak_force", r.peak_force}})
    if (!std::isfinite(value))
      throw InvalidParameter(
          "parameters",
          fmt::format("the impact leaves the double range ({} = {}): the combination of gap, velocity, masses and "
                      "law coefficients is too extreme; rescale the units so that each lies within about 1e-150 .. "
                      "1e150",
                      name, value));
}

}  // namespace

ImpactResult simulate_impact(const ImpactProblem& problem, const ImpactOptions& options) {
  check_fields(options);  // method, tolerances: the ranges ImpactOptions::describe declares
  validate::in_range("max_steps", options.max_steps, 1L, 1'000'000'000L);
  validate::non_negative("max_time", options.max_time);
  if (options.history_points != 0) validate::in_range("history_points", options.history_points, 2L, 1'000'000'000L);
  if (options.history_points > 0 && !options.on_sample) {
    // Stored history: one ImpactSample per point (plus a few events). Refuse before any work when it would not fit.
    memory::require_fits("history_points", static_cast<double>(options.history_points), sizeof(ImpactSample), 1.0);
  }

  const bool closed_form_possible = problem.law().piecewise_linear() != nullptr && problem.external().constant();
  if (options.method == ImpactMethod::closed_form && !closed_form_possible)
    throw InvalidParameter("method",
                           "method = closed_form needs a piecewise-linear law (seed-1 eqs. 10, 11, 26) and "
                           "constant external forces; use integrator or automatic");
  const bool closed = options.method == ImpactMethod::closed_form ||
                      (options.method == ImpactMethod::automatic && closed_form_possible);
  // (no computed() boundary here: the solvers check combinations of the input's scales — stiffness / reduced
  // mass, gap / speed — and refuse them as InvalidParameter naming the parameter, as input errors)
  ImpactResult r = closed ? detail::closed_form_impact(problem, options) : detail::integrated_impact(problem, options);
  require_finite_result(r);
  return r;
}

}  // namespace afmkit::impact
