// libFuzzer target: the reader of measured curves of `spectroscopy fit` (afmkit/spectroscopy/fit_input.hpp), AM
// and FM. Input = the text of a curve file. Invariants: the text is either rejected with afmkit::InputError whose
// message starts with "fuzz.csv:<line>:<column>: ", or it gives a curve of ≥ 3 rows — AM: distance and amplitude of
// equal lengths, phase empty or of the same length, amplitudes > 0; FM: distance and frequency shift of equal
// lengths, dissipation empty or of the same length; every value finite, distances distinct — that the fit's own
// validation (FitCurve::validate, FmFitCurve::validate) accepts, with the other mode's arrays empty. Nothing else
// (no crash, no other exception, no sanitizer report).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string>
#include <string_view>

#include "afmkit/core/error.hpp"
#include "afmkit/spectroscopy/fit_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  afmkit::spectroscopy::FitCurveFile file;
  try {
    file = afmkit::spectroscopy::parse_fit_curve(text, "fuzz.csv");
  } catch (const afmkit::InputError& e) {
    const std::string_view m(e.what());
    if (m.rfind("fuzz.csv:", 0) != 0) std::abort();
    // fuzz.csv:<line>:<column>: …
    std::size_t i = 9, colons = 0;
    while (i < m.size() && colons < 2) {
      if (m[i] == ':') ++colons;
      else if (m[i] < '0' || m[i] > '9') std::abort();
      ++i;
    }
    if (colons != 2) std::abort();
    return 0;
  }
  if (file.mode == afmkit::spectroscopy::FitMode::fm) {
    const auto& f = file.fm;
    const std::size_t n = f.distance.size();
    if (!file.am.distance.empty() || !file.am.amplitude.empty() || !file.am.phase.empty()) std::abort();
    if (n < 3 || f.frequency_shift.size() != n || (!f.dissipation.empty() && f.dissipation.size() != n)) std::abort();
    std::set<double> seen;
    for (std::size_t k = 0; k < n; ++k) {
      if (!std::isfinite(f.distance[k]) || !std::isfinite(f.frequency_shift[k])) std::abort();
      if (!f.dissipation.empty() && !std::isfinite(f.dissipation[k])) std::abort();
      if (!seen.insert(f.distance[k]).second) std::abort();
    }
    try {
      f.validate();
    } catch (...) {
      std::abort();
    }
    return 0;
  }
  const auto& c = file.am;
  if (!file.fm.distance.empty() || !file.fm.frequency_shift.empty() || !file.fm.dissipation.empty()) std::abort();
  const std::size_t n = c.distance.size();
  if (n < 3 || c.amplitude.size() != n || (!c.phase.empty() && c.phase.size() != n)) std::abort();
  std::set<double> seen;
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(c.distance[k]) || !std::isfinite(c.amplitude[k]) || !(c.amplitude[k] > 0.0)) std::abort();
    if (!c.phase.empty() && !std::isfinite(c.phase[k])) std::abort();
    if (!seen.insert(c.distance[k]).second) std::abort();
  }
  try {
    c.validate();
  } catch (...) {
    std::abort();  // what the reader accepts, the fit accepts
  }
  return 0;
}
