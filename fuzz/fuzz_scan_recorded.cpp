// libFuzzer target: the recorded spiral CSV reader (afmkit/scan/recorded_spiral.hpp), read to the end. Invariants
// checked on every input: reading either succeeds or throws afmkit::InputError (nothing else, from the constructor
// or from next()); after an InputError from next() the reader keeps failing; the samples have finite values, time
// and angle strictly increasing, radius >= 0; sample rate and rotation frequency are finite and positive; the
// dropped count is 0 in angle mode and >= 0 in index mode. An angle-mode recording printed back (shortest
// round-trip numbers, the unwrapped angles) reads back to the same samples bit for bit.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/scan/recorded_spiral.hpp"

namespace {

using afmkit::scan::RecordedSpiralReader;
using afmkit::scan::SpiralSample;

/// All samples of `text`, or nullopt when it is rejected (InputError; anything else escapes and crashes).
std::optional<std::vector<SpiralSample>> read(const std::string& text, bool& index_mode) {
  std::optional<RecordedSpiralReader> reader;
  try {
    reader.emplace(std::make_unique<std::istringstream>(text), "fuzz");
  } catch (const afmkit::InputError&) {
    return std::nullopt;
  }
  index_mode = reader->uses_index_pulse();
  const double rate = reader->sample_rate(), omega = reader->rotation_frequency();
  if (!std::isfinite(rate) || !(rate > 0) || !std::isfinite(omega) || !(omega > 0)) std::abort();
  std::vector<SpiralSample> samples;
  SpiralSample s{};
  try {
    while (reader->next(s)) samples.push_back(s);
  } catch (const afmkit::InputError& e) {
    try {
      reader->next(s);
    } catch (const afmkit::InputError& again) {
      if (std::strcmp(e.what(), again.what()) != 0) std::abort();
      return std::nullopt;
    }
    std::abort();  // the failure did not stay
  }
  if (reader->next(s)) std::abort();  // the end stays the end
  if (samples.size() < 2) std::abort();
  if (reader->dropped_samples() < 0 || (!index_mode && reader->dropped_samples() != 0)) std::abort();
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const SpiralSample& x = samples[k];
    if (!std::isfinite(x.time) || !std::isfinite(x.angle) || !std::isfinite(x.radius) ||
        !std::isfinite(x.deflection) || x.radius < 0)
      std::abort();
    if (k > 0 && !(x.time > samples[k - 1].time && x.angle > samples[k - 1].angle)) std::abort();
  }
  return samples;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  bool index_mode = false;
  const auto samples = read(text, index_mode);
  if (!samples || index_mode) return 0;
  std::string printed = "time,angle,radius,deflection\n";
  for (const SpiralSample& x : *samples)
    printed += fmt::format("{},{},{},{}\n", x.time, x.angle, x.radius, x.deflection);
  bool again_index = true;
  const auto back = read(printed, again_index);
  if (!back || again_index || back->size() != samples->size()) std::abort();
  if (std::memcmp(back->data(), samples->data(), samples->size() * sizeof(SpiralSample)) != 0) std::abort();
  return 0;
}
