#pragma once
// Where the scan with the controller off first saturates the detector (the scan-area comparison of virtual_scan.hpp),
// simulated only over the stretch where it can.
//
// With the controller off and no detector noise, one sample interval of the plant (seed 2, eq. 1; the height ramping
// between samples) is y_{n+1} = a y_n + b0 f_n + b1 f_{n+1} with a = e^{−γh}, b0, b1 >= 0 and a + b0 + b1 = 1
// (plant_inverse.hpp): y is a convex combination of the heights met so far, |y_n| <= max_{k<=n} |f_k|, and
// |f| <= B(r) = max |topography| + r tan ψ. No sample with B(r_n) < R_d (1 − 1e-9) can saturate (the margin covers
// rounding). The run therefore starts W samples before the first radius where B reaches R_d (rounded down to a
// multiple of 4096, where the tip angle is exact), with the plant settled on the surface (y = f): the start's error,
// at most 2B, has decayed by e^{−γ h W} <= e^{−45} (3e-20) when the possible saturation begins, far below the
// rounding of y, so the first saturated sample is the full run's (unless a reading lies within rounding of R_d;
// tested against the full run). With detector noise (unbounded) the run starts at sample 0, as before.
#include <cstdint>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/scan/instrument.hpp"
#include "afmkit/scan/surface.hpp"

namespace afmkit::scan {

struct UncontrolledSaturation {
  bool saturates = false;          ///< the uncontrolled scan saturates the detector before its end
  double radius = 0.0;             ///< r of its first saturated sample [m] (end_radius when none)
  std::int64_t first_sample = 0;   ///< where the simulation started (0: from the beginning)
  std::int64_t samples = 0;        ///< samples simulated
};

/// The first saturation of `instrument` with its controller off (the other settings as given). Cancellable.
UncontrolledSaturation first_uncontrolled_saturation(const InstrumentSpec& instrument, const Surface& surface,
                                                     const Cancellation& cancellation = {});

/// The same by the full run from sample 0 (the reference the skip is tested against; what the scan did before).
UncontrolledSaturation first_uncontrolled_saturation_full(const InstrumentSpec& instrument, const Surface& surface,
                                                          const Cancellation& cancellation = {});

}  // namespace afmkit::scan
