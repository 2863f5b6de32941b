#pragma once
// Internal pieces shared by the two impact solvers (closed form and integrator). Not installed.
#include <vector>

#include "afmkit/impact/impact.hpp"

namespace afmkit::impact::detail {

/// Closed-form solution for a piecewise-linear law and constant external forces (impact_closed_form.cpp).
ImpactResult closed_form_impact(const ImpactProblem& problem, const ImpactOptions& options);

/// Dormand–Prince integration of eq. (1) with event location (impact_integrator.cpp).
ImpactResult integrated_impact(const ImpactProblem& problem, const ImpactOptions& options);

/// Sample instants: `points` uniformly spaced on [0, end_time] merged with the event instants in
/// [0, end_time] (sorted, duplicates removed). Empty if points == 0.
std::vector<double> sample_times(double end_time, long points, const std::vector<double>& events);

/// Fills the derived quantities of `r` (restitution, energies, contact duration, eq. 6 area) from the
/// solver outputs: outcome, times, gaps, body states after the impact.
void complete_result(const ImpactProblem& problem, ImpactResult& r);

/// Largest switching gap of the law (the contact edge), NaN if the law lists none.
double contact_gap_of(const ForceLaw& law);

}  // namespace afmkit::impact::detail
