#pragma once
// The control commands' units as units::Unit (the output edge, afmkit/core/units.hpp): a rate computed in rad/s is
// shown in units of Ω (rad_per_s / Ω), a delay computed in s in units of T (seconds / T) — the operations of
// control::RotationUnits::in_omega and in_periods, so that a result's value and its unit are declared together
// (UnitTagged, io::ColumnOf).
#include "afmkit/control/units.hpp"
#include "afmkit/core/units.hpp"

namespace afmkit::cli {

struct ControlUnits {
  units::Unit omega, period;
  explicit ControlUnits(const control::RotationUnits& u)
      : omega{control::RotationUnits::rate_unit, 1.0, u.rotation_frequency()},
        period{control::RotationUnits::delay_unit, 1.0, u.period()} {}
};

}  // namespace afmkit::cli
