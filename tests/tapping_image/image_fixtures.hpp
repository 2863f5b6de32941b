#pragma once
// Shared by the tapping_image tests: the DMT + vdW cantilever of the law's defaults, and the step an image shows.
#include "afmkit/impact/force_law.hpp"
#include "afmkit/scan/height_map.hpp"
#include "afmkit/tapping/model.hpp"
#include "afmkit/tapping/units.hpp"

namespace afmkit::tapping::image::test {

/// The cantilever `pc` with DMT + vdW at the law's defaults (E* = 1 GPa, R = 10 nm, A_H = 6.4e-20 J, a0 = 0.165 nm)
/// at separation 20 (nm).
inline TappingModel dmt_defaults_model(const PhysicalCantilever& pc) {
  const impact::DmtLaw dmt(1.0, 1.0, 10.0, 6.4e-20, 6.4e-20, 0.165);
  return {pc.cantilever(), pc.drive(), pc.normalised_law(impact::ForceLaw(dmt)), 20.0};
}

/// The height image's step: mean height of the right quarter minus the left quarter of every line.
inline double right_minus_left_quarter(const scan::HeightMap& h) {
  const long nx = h.x_resolution(), ny = h.y_resolution();
  double left = 0, right = 0;
  for (long j = 0; j < ny; ++j)
    for (long i = 0; i < nx / 4; ++i) {
      left += h(i, j);
      right += h(nx - 1 - i, j);
    }
  return (right - left) / static_cast<double>(ny * (nx / 4));
}

}  // namespace afmkit::tapping::image::test
