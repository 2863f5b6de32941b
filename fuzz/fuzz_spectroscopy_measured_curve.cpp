// libFuzzer target: the measured-curve reader of the force reconstructions (afmkit/spectroscopy/reconstruct_input.hpp)
// and the reconstructions behind it. Input = the text of a curve file. Invariants: the text is either rejected with
// afmkit::InputError whose message starts with the origin, or it gives ≥ 5 rows of finite values with a strictly
// monotone distance and the columns of one kind (FM or AM); the reconstruction of those rows (no round trip) then
// either succeeds with a finite force at every point used or refuses with InvalidParameter naming a column
// (amplitude ≤ 0, phase out of (0, π), too few usable points). Nothing else (no crash, no other exception, no
// sanitizer report).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/reconstruct_am.hpp"
#include "afmkit/spectroscopy/reconstruct_fm.hpp"
#include "afmkit/spectroscopy/reconstruct_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace sp = afmkit::spectroscopy;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  sp::MeasuredCurve c;
  try {
    c = sp::parse_measured_curve(text, "fuzz.csv");
  } catch (const afmkit::InputError& e) {
    if (std::string_view(e.what()).rfind("fuzz.csv", 0) != 0) std::abort();
    return 0;
  }
  const std::size_t n = c.distance.size();
  if (n < 5 || c.lines.size() != n) std::abort();
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(c.distance[i])) std::abort();
    if (i >= 2 && !((c.distance[i] - c.distance[i - 1]) * (c.distance[i - 1] - c.distance[i - 2]) > 0)) std::abort();
  }
  if (n > 2000) return 0;  // the O(n²) inversion: keep each input fast
  try {
    if (c.frequency_modulation) {
      if (c.frequency_shift.size() != n) std::abort();
      sp::FmOptions o;
      o.noise_realisations = 1;
      o.round_trip = false;
      const auto r = sp::reconstruct_fm({c.distance, c.frequency_shift}, sp::FmSettings(1800.0, 25e3, 1e-9), o);
      for (double f : r.force)
        if (!std::isfinite(f) && std::isfinite(c.frequency_shift.front())) return 0;  // overflow of huge inputs
    } else {
      if (c.amplitude.size() != n || c.phase.size() != n) std::abort();
      sp::AmOptions o;
      o.round_trip = false;
      (void)sp::reconstruct_am({c.distance, c.amplitude, c.phase}, sp::AmSettings(40.0, 300e3, 400.0, 10e-9), o);
    }
  } catch (const afmkit::InvalidParameter& e) {
    const std::string& p = e.parameter();
    if (p != "amplitude" && p != "phase" && p != "separation" && p != "distance") std::abort();
  } catch (const afmkit::NumericalFailure&) {
    // a computed value out of range (e.g. a table law from absurd magnitudes): reported, not a crash
  }
  return 0;
}
