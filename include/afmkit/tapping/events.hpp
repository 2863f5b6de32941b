#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
// Modes, guards (witness functions) and events of the tapping cantilever (seed-1 eqs. 8, 11, 26).
//
// A mode fixes the smooth vector field used between events:
//   region  — index of the gap interval between the law's switching gaps s_0 < … < s_{m−1}
//             (region r: s_{r−1} ≤ x + l < s_r); region 0 = deepest (in contact).
//   branch  — approach (ẋ < 0, H_a), departure (ẋ > 0, H_b), or sticking (ẋ = 0 held: the tip rests).
//   contact — contact-aware laws only: the memory of contact (free: H_a whatever ẋ, no velocity guard).
// Guards, each with the crossing direction that ends the mode (Drake-style witness functions):
//   gap       x + l − s_i          falling (enter region below) or rising (enter region above)
//   velocity  ẋ                    rising in approach, falling in departure (branch switch, or sticking)
//   release   a_b(t) (departure acceleration at rest)  rising  -> leave sticking upwards
//             a_a(t) (approach acceleration at rest)   falling -> leave sticking downwards
// Crossings are isolated by bracketing root finding to a few ulps of time; the event time is taken at the
// post-crossing end of the final bracket, so the state after the event is consistent with the new mode.

namespace afmkit::tapping {

/// Tip state (x, ẋ) in model units, with the memory of a contact-aware law (docs/force-laws.md#hysteresis):
/// `contact` says whether the tip has reached the contact gap and not yet risen above the release gap. It
/// matters only for a contact-aware law with the gap between the contact and the release gaps (below the contact
/// gap the tip is in contact, above the release gap it is free, whatever the flag); ignored by velocity-sign laws.
struct TipState {
  double position = 0.0;  // x
  double velocity = 0.0;  // ẋ
  bool contact = false;   // memory of contact (contact-aware laws)
  /// A multi-mode cantilever (modes.hpp): the higher modal coordinates (q_2, q̇_2, q_3, q̇_3); x and ẋ stay the
  /// tip's, so the guards are those of one mode. Zero (unused) for a single-mode cantilever.
  std::array<double, 4> modal{};
};

/// Which force branch is active (seed-1 eq. 4 as corrected in docs/theory-tapping.md#impact).
enum class ContactBranch { approach, departure, sticking };
const char* contact_branch_name(ContactBranch branch);

struct Mode {
  int region = 0;  // gap interval index (0 = below the lowest switching gap)
  ContactBranch branch = ContactBranch::approach;
  /// Contact-aware laws: in contact (branch by the velocity sign) or free (always the approach branch, no
  /// velocity guard); set on the gap falling through the contact gap, cleared on it rising through the release
  /// gap. Always false for velocity-sign laws.
  bool contact = false;
  friend bool operator==(const Mode&, const Mode&) = default;
};

/// Kinds of guard (witness) functions.
enum class GuardKind { gap, velocity, release_departure, release_approach };
const char* guard_kind_name(GuardKind kind);

enum class CrossingDirection { rising, falling };

struct Guard {
  GuardKind kind = GuardKind::gap;
  CrossingDirection direction = CrossingDirection::falling;
  double level = 0.0;  // switching gap s_i for GuardKind::gap, 0 otherwise
};

/// A located mode switch.
struct Event {
  double time = 0.0;
  Guard guard;
  Mode before;
  Mode after;
  TipState state;  // state at the event (after the switch)
};

/// Isolate the crossing of a scalar witness `g` over [t_lo, t_hi] given that g(t_lo) is strictly on the
/// pre-crossing side and g(t_hi) on the post-crossing side (or zero) for `direction`. Returns the post-crossing
/// end of the final bracket, which shrinks to at most `time_tolerance` (or to adjacent doubles). Pure
/// bracketing (secant/bisection, Illinois-safeguarded), so it never leaves [t_lo, t_hi].
template <class Witness>
double isolate_crossing(Witness&& g, double t_lo, double t_hi, CrossingDirection direction, double time_tolerance) {
  // Orient so that the pre-crossing side is positive.
  const double sign = direction == CrossingDirection::falling ? 1.0 : -1.0;
  double a = t_lo, b = t_hi;
  double fa = sign * g(a), fb = sign * g(b);
  int side = 0;
  for (int it = 0; it < 200 && b - a > time_tolerance; ++it) {
    // regula falsi (Illinois) step, falling back to bisection when it stalls
    double c = (fb < 0.0 && fa > 0.0) ? b - fb * (b - a) / (fb - fa) : 0.5 * (a + b);
    if (!(c > a && c < b) || (it % 4 == 3)) c = 0.5 * (a + b);
    if (c <= a || c >= b) break;  // adjacent doubles
    const double fc = sign * g(c);
    if (fc > 0.0) {
      a = c;
      fa = fc;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = c;
      fb = fc;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return b;
}

/// As isolate_crossing, with the witness rate available: `g(t)` returns {value, rate}. Safeguarded Newton
/// (falls back to bisection when a step leaves the bracket or progress stalls); the result is still the
/// post-crossing end of a bracket no wider than `time_tolerance`. g_lo, g_hi: witness values at the ends.
template <class WitnessWithRate>
double isolate_crossing_newton(WitnessWithRate&& g, double t_lo, double g_lo, double t_hi, double g_hi,
                               CrossingDirection direction, double time_tolerance) {
  const double sign = direction == CrossingDirection::falling ? 1.0 : -1.0;
  double a = t_lo, b = t_hi;
  const double fa = sign * g_lo, fb = sign * g_hi;
  double t = (fa > 0.0 && fb < 0.0) ? b - fb * (b - a) / (fb - fa) : 0.5 * (a + b);
  if (!(t > a && t < b)) t = 0.5 * (a + b);
  double dx = b - a, dx_old = dx;
  for (int it = 0; it < 100 && b - a > time_tolerance; ++it) {
    auto [f, r] = g(t);
    f *= sign, r *= sign;
    if (f > 0.0) a = t; else b = t;
    if (b - a <= time_tolerance) break;
    // Newton step unless it leaves the bracket or does not halve the step before last (rtsafe rule)
    dx_old = dx;
    const double newton = r != 0.0 ? t - f / r : std::numeric_limits<double>::quiet_NaN();
    double next;
    if (newton >= a - time_tolerance && newton <= b + time_tolerance &&
        (std::abs(newton - a) < time_tolerance || std::abs(newton - b) < time_tolerance ||
         std::abs(newton - t) < time_tolerance)) {
      // the root is pinned to within the tolerance: close the bracket around it with two probes
      // (the side the last iterate t already pins needs no probe)
      const double c = std::clamp(newton, a, b);
      const double lo = std::max(a, c - 0.4 * time_tolerance), hi = std::min(b, c + 0.4 * time_tolerance);
      if (lo > a && !(t == a && a >= lo - time_tolerance) && sign * g(lo).first > 0.0) a = lo;
      if (b - a > time_tolerance && hi < b && sign * g(hi).first <= 0.0) b = hi;
      if (b - a <= time_tolerance) break;
      dx = 0.5 * (b - a);
      next = a + dx;
    } else if (!(newton > a && newton < b) || std::abs(2.0 * f) > std::abs(dx_old * r)) {
      dx = 0.5 * (b - a);
      next = a + dx;
    } else {
      dx = t - newton;
      next = newton;
    }
    if (next <= a || next >= b) break;  // adjacent doubles
    t = next;
  }
  return b;
}

/// True if the witness values (before, after) show a crossing in `direction` (pre-crossing side strict).
inline bool crosses(double before, double after, CrossingDirection direction) {
  return direction == CrossingDirection::falling ? (before > 0.0 && after <= 0.0) : (before < 0.0 && after >= 0.0);
}

}  // namespace afmkit::tapping
