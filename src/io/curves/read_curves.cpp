#include "afmkit/io/curves/read_curves.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"
#include "binary_readers.hpp"
#include "text_reader.hpp"
#include "text_table.hpp"

namespace afmkit::io::curves {

namespace {

std::string extension_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  return path.substr(dot);
}

// The format of `bytes` when the options say "auto": the content first (a zip archive is a JPK file, an Igor
// binary wave starts with its version), then the extension.
std::string detect_format(std::string_view bytes, const std::string& extension) {
  const std::string ext = detail::lower(extension);
  if (bytes.size() >= 4 && bytes.substr(0, 4) == std::string_view("PK\x03\x04", 4)) return "jpk-force";
  if (ext == ".jpk-force" || ext == ".jpk-force-map" || ext == ".jpk-qi-data") return "jpk-force";
  // An Igor binary wave: version 5 (either byte order) in its first two bytes and room for its headers.
  if (bytes.size() >= 384 && (bytes.substr(0, 2) == std::string_view("\x05\x00", 2) ||
                              bytes.substr(0, 2) == std::string_view("\x00\x05", 2)))
    return "ibw";
  if (ext == ".ibw" || ext == ".bwav") return "ibw";
  return "text";
}

void check_calibration(double value, const char* name, const char* unit, const std::string& origin) {
  if (std::isnan(value)) return;
  if (!std::isfinite(value) || value <= 0)
    throw InputError(fmt::format("{}: {} = {} {}: must be a positive finite number", origin, name, value, unit));
}

// Every reader's output obeys raw_curve.hpp: finite values in SI (a huge encoder multiplier or a float32
// overflow can still make one infinite after conversion), channels of equal length, no empty segment.
void validate(const RawCurve& curve) {
  if (curve.segments.empty()) throw InputError(fmt::format("{}: no segment with data", curve.origin));
  for (std::size_t s = 0; s < curve.segments.size(); ++s) {
    const Segment& seg = curve.segments[s];
    const std::size_t n = seg.size();
    if (n == 0) throw InputError(fmt::format("{}: segment {} has no samples", curve.origin, s + 1));
    const std::pair<const char*, const std::vector<double>*> channels[] = {
        {"height", &seg.height}, {"deflection", &seg.deflection}, {"deflection signal", &seg.deflection_volts},
        {"force", &seg.force}, {"time", &seg.time}};
    for (const auto& [name, v] : channels) {
      if (!v->empty() && v->size() != n)
        throw NumericalFailure(fmt::format("{}: segment {}: the {} has {} samples, the segment {} (reader defect)",
                                           curve.origin, s + 1, name, v->size(), n));
      for (std::size_t i = 0; i < v->size(); ++i)
        if (!std::isfinite((*v)[i]))
          throw InputError(fmt::format("{}: segment {} ({}), sample {}: the {} is not finite after conversion to SI "
                                       "units",
                                       curve.origin, s + 1, to_string(seg.kind), i + 1, name));
    }
  }
  const auto& m = curve.metadata;
  for (const auto& [name, v] : {std::pair{"spring constant", m.spring_constant}, std::pair{"InvOLS", m.invols},
                                std::pair{"resonance frequency", m.resonance_frequency},
                                std::pair{"quality factor", m.quality_factor}})
    if (!std::isnan(v) && !(std::isfinite(v) && v > 0))
      throw InputError(fmt::format("{}: the file's {} is {}: must be positive and finite", curve.origin, name, v));
}

}  // namespace

std::vector<RawCurve> parse_curves(std::string_view bytes, const std::string& origin, const std::string& extension,
                                   const ReadOptions& options) {
  check_calibration(options.spring_constant, "spring constant", "N/m", origin);
  check_calibration(options.invols, "InvOLS", "m/V", origin);
  const std::string format = options.format == "auto" ? detect_format(bytes, extension) : options.format;
  std::vector<RawCurve> curves;
  if (format == "jpk-force") {
    curves = detail::read_jpk_force(bytes, origin, options);
  } else if (format == "ibw") {
    curves = detail::read_ibw(bytes, origin, options);
  } else if (detail::is_text_format(format)) {
    ReadOptions o = options;
    o.format = format;
    curves = detail::read_text_curves(bytes, origin, o);
  } else {
    throw InputError(fmt::format("{}: format '{}' is not one of auto, jpk-force, ibw, text, jpk-txt, asylum-txt, "
                                 "nanoscope-txt, ntmdt-txt, afmworkshop-csv",
                                 origin, format));
  }
  for (RawCurve& c : curves) {
    if (!std::isnan(options.spring_constant)) c.metadata.spring_constant = options.spring_constant;
    if (!std::isnan(options.invols)) c.metadata.invols = options.invols;
    validate(c);
  }
  return curves;
}

std::vector<RawCurve> read_curves(const std::string& path, const ReadOptions& options) {
  const std::string bytes = files::read_input_file(path, "force curve");
  return parse_curves(bytes, path, extension_of(path), options);
}

}  // namespace afmkit::io::curves
