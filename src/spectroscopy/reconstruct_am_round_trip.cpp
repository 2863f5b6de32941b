// The AM round trip: the reconstructed table law through afmkit's exact orbits (tapping sweep, approach) at the
// measured settings, A/A0 and phase compared with the measurement (reconstruct_am.hpp).
#include "reconstruct_am_round_trip.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "afmkit/core/error.hpp"
#include "afmkit/tapping/orbit.hpp"
#include "afmkit/tapping/shooting.hpp"
#include "afmkit/tapping/sweep.hpp"
#include "afmkit/tapping/transient.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::spectroscopy {

void am_round_trip(AmReconstruction& r, const AmSettings& s, bool dissipative, int points) {
  const tapping::PhysicalCantilever pc(s.spring_constant, s.resonance_frequency * 1e-3, s.quality_factor,
                                       s.free_amplitude * 1e9, s.frequency_ratio());
  // velocity-sign switching (seed-1 eq. 4), not the table law's contact-aware default: the inversion turns the
  // dissipation measured at lower turning point D into the branch difference at D, which an orbit reaching D
  // dissipates under that rule whether or not it reached the contact gap (docs/reconstruction.md#round-trip)
  const impact::ForceLaw physical =
      impact::make_law<impact::TableLaw>(r.law, !dissipative, impact::Hysteresis::velocity);
  const std::vector<double>& l = r.separation;
  std::vector<double> l_nm;
  for (double x : l) l_nm.push_back(x * 1e9);
  // the separations of the round trip: every one, or `points` evenly spread (the ends included)
  std::vector<double> visit;
  const std::size_t m = l.size();
  if (points == 0 || static_cast<std::size_t>(points) >= m) visit = l_nm;
  else
    for (int j = 0; j < points; ++j)
      visit.push_back(l_nm[static_cast<std::size_t>(std::llround(static_cast<double>(j) * (m - 1) / (points - 1)))]);
  const tapping::TappingModel model(pc.cantilever(), pc.drive(), pc.normalised_law(physical), l_nm.back());
  tapping::SweepOptions options;
  options.harmonic_balance = false;
  // a transient after a jump settles within a few Q periods; 20 Q bounds one that does not (instead of 20000)
  options.transient.max_periods = static_cast<int>(std::clamp(20.0 * s.quality_factor, 500.0, 20000.0));
  // the approach only (an instrument sweep would also retract): from the free orbit at the largest separation,
  // each orbit continued from the previous one along its branch (tapping::follow_stable_branch, as the sweep does);
  // where the branch ends, the transient from the last stable orbit settles on another (a jump)
  const std::size_t n = l.size();
  r.round_trip_amplitude_ratio.assign(n, std::numeric_limits<double>::quiet_NaN());
  r.round_trip_phase = r.residual_amplitude_ratio = r.residual_phase = r.round_trip_amplitude_ratio;
  std::vector<double> jumps;
  std::optional<tapping::PeriodicOrbit> orbit;
  tapping::TipState state;
  for (std::size_t v = visit.size(); v-- > 0;) {
    const double at = visit[v];
    const tapping::TappingModel here = model.with_separation(at);
    if (!orbit) {
      const tapping::TipState start = v + 1 == visit.size() ? tapping::free_response_state(here) : state;
      try {
        if (v + 1 == visit.size()) orbit = tapping::try_shoot(here, start, 1, options.shooting);
      } catch (const NumericalFailure&) {
        orbit.reset();
      }
      if (!orbit || !orbit->stable) {
        const tapping::TransientOutcome t = tapping::settle(here, start, options.transient, options.shooting);
        orbit = t.orbit;
        state = t.final_state;
      }
    } else {
      const tapping::BranchFollow f = tapping::follow_stable_branch(model, *orbit, at, options);
      if (f.reached) {
        orbit = f.reached;
      } else {
        const tapping::TransientOutcome t = tapping::settle(here, f.last.initial, options.transient, options.shooting);
        jumps.push_back(at);
        orbit = t.orbit;
        state = t.final_state;
      }
    }
    if (!orbit) continue;  // not settled: no value at this separation
    const tapping::OrbitMetrics metrics = tapping::analyse_orbit(here, *orbit, options.shooting.simulation);
    const std::size_t i = static_cast<std::size_t>(std::lower_bound(l_nm.begin(), l_nm.end(), at) - l_nm.begin());
    r.round_trip_amplitude_ratio[i] = metrics.amplitude / (s.free_amplitude * 1e9);
    r.round_trip_phase[i] = metrics.phase;
  }
  double sa = 0.0, sp = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(r.round_trip_amplitude_ratio[i])) continue;
    r.residual_amplitude_ratio[i] = r.round_trip_amplitude_ratio[i] - r.amplitude[i] / s.free_amplitude;
    r.residual_phase[i] = r.round_trip_phase[i] - r.phase[i];
    sa += r.residual_amplitude_ratio[i] * r.residual_amplitude_ratio[i];
    sp += r.residual_phase[i] * r.residual_phase[i];
    ++count;
  }
  r.rms_amplitude_ratio = count ? std::sqrt(sa / static_cast<double>(count)) : std::numeric_limits<double>::quiet_NaN();
  r.rms_phase = count ? std::sqrt(sp / static_cast<double>(count)) : std::numeric_limits<double>::quiet_NaN();
  r.round_trip_orbits = static_cast<int>(count);
  r.round_trip_model = fmt::format("exact periodic orbits of the table law (tapping sweep, approach) at {} of the {} "
                                   "measured separations; branches chosen by the sign of the velocity (run the law with "
                                   "--hysteresis velocity to reproduce it)",
                                   count, n);
  if (!jumps.empty())
    r.notes.push_back(fmt::format("the round trip jumped to another branch at l = {} nm (approach): where the measured "
                                  "curve stays on one branch, the reconstructed law does not hold it there (the law "
                                  "below the smallest D reached is an extrapolation)",
                                  fmt::join(jumps, ", ")));
}

}  // namespace afmkit::spectroscopy
