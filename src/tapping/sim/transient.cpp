#include "afmkit/tapping/transient.hpp"

#include <cmath>
#include <deque>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/validate.hpp"
#include "phase_space.hpp"

namespace afmkit::tapping {

void TransientOptions::validate() const {
  validate::require(chunk_periods >= 1, "chunk_periods", chunk_periods, ">= 1");
  check_fields(*this);  // the ranges describe() declares
  validate::require(max_periods >= chunk_periods, "max_transient_periods", max_periods, ">= chunk_periods");
  validate::require(capture_distance > 0 && capture_distance < 1, "capture_distance", capture_distance, "in (0, 1)");
}

const char* response_kind_name(ResponseKind kind) {
  return kind == ResponseKind::periodic ? "periodic" : "not_settled";
}

namespace {


}  // namespace

TransientOutcome settle(const TappingModel& model, TipState start, const TransientOptions& options,
                        const ShootingOptions& shooting) {
  options.validate();
  shooting.validate();
  const double period = model.period();
  const double omega = model.drive.frequency;
  // Newton inside a transient gets a small budget: it is retried after every chunk.
  ShootingOptions quick = shooting;
  quick.max_iterations = std::min(quick.max_iterations, 10);
  SimulationOptions sim = shooting.simulation;
  sim.sensitivity = false;

  TransientOutcome out;
  const int nmax = options.max_period_multiple;
  std::deque<TipState> strobe{start};  // the last nmax + 1 stroboscopic points y_k = x(kT)
  int k = 0;                           // periods simulated
  TipState y = start;
  // The drive is T-periodic: every period restarts at t = 0, which keeps the drive phase exact.
  auto advance = [&](int periods) {
    for (int i = 0; i < periods; ++i) {
      y = simulate(model, 0.0, y, period, sim).state;
      strobe.push_back(y);
      if (static_cast<int>(strobe.size()) > nmax + 1) strobe.pop_front();
      ++k;
    }
  };
  std::optional<PeriodicOrbit> candidate;
  double candidate_distance = 0.0;
  while (k < options.max_periods) {
    options.cancellation.check();
    advance(options.chunk_periods);
    if (options.on_periods) options.on_periods(options.chunk_periods);
    const int last = static_cast<int>(strobe.size()) - 1;
    const double scale = std::max(1e-9, detail::phase_magnitude(y, omega));
    if (candidate) {
      // verify the capture: the distance to the candidate orbit point of the same phase keeps decreasing
      const int n = candidate->period_multiple;
      double d = 1e300;
      TipState p = candidate->initial;
      for (int j = 0; j < n; ++j) {
        d = std::min(d, detail::phase_distance(y, p, omega));
        p = simulate(model, 0.0, p, period, sim).state;
      }
      if (d < candidate_distance || d <= 1e3 * shooting.tolerance * scale) {
        out.kind = ResponseKind::periodic;
        out.orbit = candidate;
        out.periods_simulated = k;
        out.final_state = y;
        return out;
      }
      candidate.reset();
    }
    // stroboscopic differences over n periods suggest which period to look for
    std::vector<double> diff(nmax + 1, 1e300);
    for (int n = 1; n <= nmax && n <= last; ++n) diff[n] = detail::phase_distance(strobe[last], strobe[last - n], omega);
    for (int n = 1; n <= nmax && n <= last; ++n) {
      if (n > 1 && !(diff[n] < 0.5 * diff[1])) continue;
      std::optional<PeriodicOrbit> orbit;
      try {
        orbit = try_shoot(model, y, n, quick);
      } catch (const NumericalFailure&) {
        orbit.reset();
      }
      if (!orbit) continue;
      const double d = detail::phase_distance(y, orbit->initial, omega);
      // The simulated response itself repeats after n periods to the shooting tolerance (e.g. a tip resting in
      // the sticking mode: neutrally stable, multipliers 1 and 0): it is that orbit, whatever its multipliers.
      if (diff[n] <= 100.0 * shooting.tolerance * scale && d <= 100.0 * shooting.tolerance * scale) {
        out.kind = ResponseKind::periodic;
        out.orbit = orbit;
        out.periods_simulated = k;
        out.final_state = y;
        return out;
      }
      if (!orbit->stable) continue;
      if (d <= options.capture_distance * std::max(scale, detail::phase_magnitude(orbit->initial, omega))) {
        candidate = orbit;
        candidate_distance = d;
        break;
      }
    }
  }
  out.kind = ResponseKind::not_settled;
  out.periods_simulated = k;
  out.final_state = y;
  out.message = fmt::format("no stable periodic orbit of period <= {} captured the response within {} drive periods "
                            "(non-periodic, longer period, or slower transient)",
                            nmax, options.max_periods);
  return out;
}

}  // namespace afmkit::tapping
