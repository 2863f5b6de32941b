#include "afmkit/impact/impact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "impact_detail.hpp"

namespace afmkit::impact {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

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
}

ImpactProblem ImpactProblem::head_on(double mass1, double mass2, double approach_speed, double gap, ForceLaw law) {
  validate::positive("mass1", mass1);
  validate::positive("mass2", mass2);
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
  return (1.0 - e * e) * m1 * m2 / (2.0 * (m1 + m2)) * relative_velocity * relative_velocity;  // eq. (3)
}

namespace detail {

double contact_gap_of(const ForceLaw& law) {
  const auto& gaps = law.switching_gaps();
  return gaps.empty() ? nan : gaps.back();
}

std::vector<double> sample_times(double end_time, long points, const std::vector<double>& events) {
  std::vector<double> t;
  if (points <= 0) return t;
  t.reserve(static_cast<std::size_t>(points) + events.size());
  for (long k = 0; k < points; ++k) t.push_back(end_time * static_cast<double>(k) / static_cast<double>(points - 1));
  t.back() = end_time;
  for (double e : events)
    if (e >= 0 && e <= end_time) t.push_back(e);
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

void complete_result(const ImpactProblem& problem, ImpactResult& r) {
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
    r.departure_gap_rate = rel_f;
    r.restitution = -rel_f / rel_s;  // eq. (2)
    r.kinetic_energy_loss =
        0.5 * total * (com_s - com_f) * (com_s + com_f) + 0.5 * mu * (rel_s - rel_f) * (rel_s + rel_f);
    r.energy_loss_restitution = (1.0 - r.restitution * r.restitution) * 0.5 * mu * rel_s * rel_s;  // eq. (3)
    r.energy_loss_area = hysteresis_energy_loss(problem.law(), r.minimum_gap, r.reference_gap);  // eq. (6)
  } else {
    r.departure_gap_rate = r.restitution = nan;
    r.kinetic_energy_loss = r.energy_loss_restitution = r.energy_loss_area = nan;
  }
}

}  // namespace detail

ImpactResult simulate_impact(const ImpactProblem& problem, const ImpactOptions& options) {
  validate::require(options.relative_tolerance > 0 && options.relative_tolerance <= 1e-2, "relative_tolerance",
                    options.relative_tolerance, "in (0, 1e-2]");
  validate::positive("absolute_tolerance", options.absolute_tolerance);
  validate::in_range("max_steps", options.max_steps, 1L, 1'000'000'000L);
  validate::non_negative("max_time", options.max_time);
  if (options.history_points != 0) validate::in_range("history_points", options.history_points, 2L, 100'000'000L);

  const bool closed_form_possible = problem.law().piecewise_linear() != nullptr && problem.external().constant();
  switch (options.method) {
    case ImpactMethod::closed_form:
      if (!closed_form_possible)
        throw InvalidParameter("method",
                               "method = closed_form needs a piecewise-linear law (seed-1 eqs. 10, 11, 26) and "
                               "constant external forces; use integrator or automatic");
      return detail::closed_form_impact(problem, options);
    case ImpactMethod::integrator:
      return detail::integrated_impact(problem, options);
    case ImpactMethod::automatic:
    default:
      return closed_form_possible ? detail::closed_form_impact(problem, options)
                                  : detail::integrated_impact(problem, options);
  }
}

}  // namespace afmkit::impact
