#pragma once
// Internal: the integration engine shared by the closed-form and the adaptive steppers — run state, the guard
// scan of one interval, event handling with saltation matrices, and the sticking mode.
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include <Eigen/Core>

#include "afmkit/tapping/events.hpp"
#include "afmkit/tapping/observer.hpp"
#include "afmkit/tapping/simulation.hpp"
#include "afmkit/tapping/system.hpp"

namespace afmkit::tapping::detail {

struct RunState {
  double t = 0.0;
  TipState y;
  Mode mode;
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Identity();  // ∂(x, ẋ, l)(t)/∂(x, ẋ, l)(t_begin)
  SimulationStats stats;
};

inline double time_tolerance(double t) { return 8.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t)); }

/// Witness values and rates of the active guards at one instant.
struct GuardSamples {
  std::array<double, 3> value{};
  std::array<double, 3> rate{};
};

inline void sample_guards(const TappingSystem& sys, const Mode& mode, const std::array<Guard, 3>& guards, int n,
                          double t, TipState s, GuardSamples& out) {
  for (int i = 0; i < n; ++i) {
    out.value[i] = sys.witness(guards[i], mode, t, s);
    out.rate[i] = sys.witness_rate(guards[i], mode, t, s);
  }
}

/// At the start of a segment (just after an event) the witness of the guard that ends the new mode is zero up to
/// the rounding of the event location, possibly on its post-crossing side (e.g. entering contact with the gap
/// at +1e-16: the exit guard "gap rising through 0" then looks already crossed). When the witness rate points
/// into the pre-crossing side, the state is on the pre side an instant later: record it as such, so a short
/// excursion (a grazing contact shorter than one scan step) is not missed by the sign test of first_crossing.
inline void start_on_pre_side(const std::array<Guard, 3>& guards, int n, double scale, GuardSamples& a) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  for (int i = 0; i < n; ++i) {
    const bool falling = guards[i].direction == CrossingDirection::falling;
    const double v = a.value[i], r = a.rate[i];
    const bool post_or_zero = falling ? v <= 0.0 : v >= 0.0;
    const bool into_pre = falling ? r > 0.0 : r < 0.0;
    if (post_or_zero && into_pre && std::abs(v) <= 1e3 * eps * scale)
      a.value[i] = falling ? std::numeric_limits<double>::denorm_min() : -std::numeric_limits<double>::denorm_min();
  }
}

struct Crossing {
  double time;
  int guard;
};

/// Earliest crossing of an active guard inside [ta, tb], given the samples at both ends. Detects a sign change,
/// and also a double crossing hidden between two samples on the pre-crossing side (the witness rate changes
/// sign towards the post side: the extremum is located and tested). `state(t)` evaluates the flow.
template <class StateFn>
std::optional<Crossing> first_crossing(const TappingSystem& sys, const Mode& mode, const std::array<Guard, 3>& guards,
                                       int n, double ta, double tb, const GuardSamples& a, const GuardSamples& b,
                                       StateFn&& state) {
  std::optional<Crossing> best;
  for (int i = 0; i < n; ++i) {
    const Guard& g = guards[i];
    auto witness = [&](double t) { return sys.witness(g, mode, t, state(t)); };
    double hi = tb, g_hi = b.value[i];
    bool found = crosses(a.value[i], b.value[i], g.direction);
    if (!found) {
      const bool falling = g.direction == CrossingDirection::falling;
      const bool pre_a = falling ? a.value[i] > 0 : a.value[i] < 0;
      const bool pre_b = falling ? b.value[i] > 0 : b.value[i] < 0;
      const bool towards = falling ? (a.rate[i] < 0 && b.rate[i] > 0) : (a.rate[i] > 0 && b.rate[i] < 0);
      if (pre_a && pre_b && towards) {
        auto rate = [&](double t) {
          const TipState s = state(t);
          return std::pair<double, double>(sys.witness_rate(g, mode, t, s), sys.witness_rate_derivative(g, mode, t, s));
        };
        const double tm = isolate_crossing_newton(rate, ta, a.rate[i], tb, b.rate[i],
                                                  falling ? CrossingDirection::rising : CrossingDirection::falling,
                                                  time_tolerance(tb));
        const double gm = witness(tm);
        if (crosses(a.value[i], gm, g.direction)) {
          found = true;
          hi = tm;
          g_hi = gm;
        }
      }
    }
    if (!found) continue;
    auto witness_and_rate = [&](double t) {
      const TipState s = state(t);
      return std::pair<double, double>(sys.witness(g, mode, t, s), sys.witness_rate(g, mode, t, s));
    };
    const double te =
        isolate_crossing_newton(witness_and_rate, ta, a.value[i], hi, g_hi, g.direction, time_tolerance(hi));
    if (!best || te < best->time) best = Crossing{te, i};
  }
  return best;
}

/// Apply an event at time te: pre_state = state reached by the flow of the old mode. Updates mode, state,
/// statistics, the sensitivity (saltation matrix), notifies the observer; throws when the event budget ends.
void handle_event(const TappingSystem& sys, RunState& rs, const Guard& guard, double te, TipState pre_state,
                  const SimulationOptions& options, TrajectoryObserver* observer);

/// Sticking mode: the tip rests at rs.y.position until a release guard fires or t_end.
void run_sticking(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
                  TrajectoryObserver* observer);

/// Scan step bound: fraction of the shortest period present.
double scan_step(const TappingSystem& sys, double mode_period, const SimulationOptions& options);

void run_closed_form(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
                     TrajectoryObserver* observer);
void run_adaptive(const TappingSystem& sys, RunState& rs, double t_end, const SimulationOptions& options,
                  TrajectoryObserver* observer);

}  // namespace afmkit::tapping::detail
