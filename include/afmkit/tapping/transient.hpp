#pragma once
// Transients: simulate from a state until the stroboscopic sequence settles, detect its period (1..4 drive
// periods) and converge it by shooting. What a physical instrument does when an orbit disappears (a jump).
#include <functional>
#include <optional>
#include <string>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/tapping/shooting.hpp"

namespace afmkit::tapping {

struct TransientOptions {
  int chunk_periods = 24;       // periods between checks (a multiple of 1..4 keeps the phase of period-n orbits)
  int max_periods = 20000;      // give up (non-periodic / not settled) after this many periods
  int max_period_multiple = 4;  // look for period-n responses, n = 1..max_period_multiple
  /// Accept the shooting result once the simulated state is within this distance (relative to the orbit
  /// amplitude) of a stable orbit of matching period, and the distance keeps decreasing.
  double capture_distance = 0.02;
  /// If set, called after every chunk with the periods just simulated (progress of long transients; settle() may
  /// run on several threads at once, so it must be thread-safe).
  std::function<void(int)> on_periods{};
  /// Checked after every chunk of chunk_periods periods (a long transient stops within a chunk on request;
  /// core/cancellation.hpp). find_orbits and the sweeps pass their own cancellation here.
  Cancellation cancellation{};

  /// The fields a user sets, declared once (core/describe.hpp). max_periods must also be >= chunk_periods.
  template <class Archive, class Self>
  static void describe(Archive& a, Self& o) {
    a.integer("max_period_multiple", o.max_period_multiple, "look for period-n responses up to this n", 1, 16);
    a.integer("max_transient_periods", o.max_periods, "drive periods a transient may take to settle", 24, 100000000);
  }
  void validate() const;  // InvalidParameter naming the key
};

enum class ResponseKind { periodic, not_settled };
const char* response_kind_name(ResponseKind kind);

struct TransientOutcome {
  ResponseKind kind = ResponseKind::not_settled;
  std::optional<PeriodicOrbit> orbit;  // set when kind == periodic (stable, period_multiple = n)
  int periods_simulated = 0;
  TipState final_state;  // state at the last stroboscopic instant (t = k T) simulated
  std::string message;   // e.g. why it was reported not settled
};

/// Simulate from `start` (at drive phase 0) at model.separation until a stable periodic orbit of period
/// n ≤ max_period_multiple captures the trajectory. A response that does not settle in max_periods (e.g.
/// chaotic, or period > max_period_multiple) is reported as not_settled, never an endless loop.
TransientOutcome settle(const TappingModel& model, TipState start, const TransientOptions& options = {},
                        const ShootingOptions& shooting = {});

}  // namespace afmkit::tapping
