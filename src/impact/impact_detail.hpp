#pragma once
// Internal pieces shared by the two impact solvers (closed form and integrator). Not installed.
#include <functional>
#include <limits>
#include <vector>

#include "afmkit/impact/impact.hpp"

namespace afmkit::impact::detail {

/// Closed-form solution for a piecewise-linear law and constant external forces (impact_closed_form.cpp).
ImpactResult closed_form_impact(const ImpactProblem& problem, const ImpactOptions& options);

/// Dormand–Prince integration of eq. (1) with event location (impact_integrator.cpp).
ImpactResult integrated_impact(const ImpactProblem& problem, const ImpactOptions& options);

/// Sample instants, generated one at a time (no array of `points` instants): `points` uniformly spaced on
/// [0, end_time] merged with the event instants in [0, end_time], ascending, exact duplicates removed.
/// Nothing if points == 0.
class SampleClock {
 public:
  SampleClock(double end_time, long points, std::vector<double> events);
  bool done() const { return !has_next_; }
  double peek() const { return next_; }  ///< only if !done()
  void pop();

 private:
  double end_time_;
  long points_;
  long k_ = 0;            // next uniform index
  std::size_t j_ = 0;     // next event index
  std::vector<double> events_;
  double next_ = 0;
  bool has_next_ = false;
  bool have_last_ = false;
  double last_ = 0;
  double uniform(long k) const;
  void advance();
};

/// Where history samples go: options.on_sample if set, else result.history.
class HistorySink {
 public:
  HistorySink(const ImpactOptions& options, std::vector<ImpactSample>& history)
      : callback_(options.on_sample ? &options.on_sample : nullptr), history_(history) {}
  void operator()(const ImpactSample& s) const {
    if (callback_) (*callback_)(s);
    else history_.push_back(s);
  }

 private:
  const std::function<void(const ImpactSample&)>* callback_;
  std::vector<ImpactSample>& history_;
};

/// Fills the derived quantities of `r` (restitution, energies, contact duration, eq. 6 area) from the
/// solver outputs: outcome, times, gaps, body states after the impact. `relative_loss` = kinetic-energy loss of
/// the relative motion, ½ μ (ḋ(t_s)² − ḋ(t_f)²), when the solver knows it without cancellation (closed form:
/// the eq. 6 area); then the loss, e and 1 − e are derived from it. NaN: from the body states.
void complete_result(const ImpactProblem& problem, ImpactResult& r, double relative_loss = std::numeric_limits<double>::quiet_NaN());

/// Largest switching gap of the law (the contact edge), NaN if the law lists none.
double contact_gap_of(const ForceLaw& law);

}  // namespace afmkit::impact::detail
