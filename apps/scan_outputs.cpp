// Outputs of `afmkit scan` (scan_outputs.hpp).
#include "scan_outputs.hpp"

#include <cmath>
#include <deque>
#include <future>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

#include "afmkit/scan/gsf.hpp"
#include "afmkit/scan/levelling.hpp"
#include "afmkit/scan/png16.hpp"

namespace afmkit::cli {

namespace {
std::vector<io::Column> series_columns(bool recorded) {
  if (recorded)
    return {{"time", "s", "time of the sample"},
            {"radius", "m", "radius of the tip on the sample"},
            {"angle", "rad", "spindle angle, unwrapped"},
            {"deflection", "m", "recorded deflection"},
            {"control", "m/s", "output u of the real-time filter (virtual static plant, see docs/scan.md)"},
            {"tilt_free", "m", "deflection + u/K: the signal with its first harmonic removed"}};
  return {{"time", "s", "time of the sample"},
          {"radius", "m", "radius r of the tip on the sample"},
          {"angle", "rad", "spindle angle theta = Omega t, unwrapped"},
          {"deflection", "m", "detector reading d (clamped to +-detector_range)"},
          {"control", "m/s", "controller output u (seed 2, eq. 1)"},
          {"actuator", "m", "calibrated actuator displacement (minus the nominal plant response to u)"},
          {"topography", "m", "lagged reconstruction: deflection + actuator"},
          {"surface", "m", "true height under the tip (topography + tilt)"},
          {"saturated", "boolean", "1 when the detector saturated at this sample"},
          {"topography_inverse", "m", "inverse reconstruction: the plant's lag removed (NaN: saturated or settling)"}};
}
}  // namespace

SeriesWriter::SeriesWriter(const std::string& path, long every, bool recorded)
    : writer_(path, series_columns(recorded)), every_(every), recorded_(recorded) {}

bool SeriesWriter::sample(const scan::ScanSample& s) {
  if (s.index % every_ != 0) return true;
  if (recorded_)
    writer_.row(s.time, s.radius, s.angle, s.deflection, s.control, s.topography);
  else
    writer_.row(s.time, s.radius, s.angle, s.deflection, s.control, s.actuator, s.topography, s.surface,
                s.saturated, s.inverse);
  return true;
}

PointCloud::PointCloud(long every, bool recorded, std::size_t expected, bool inverse)
    : every_(every), recorded_(recorded), inverse_(inverse) {
  for (auto* v : {&x_, &y_, &a_, &b_}) v->reserve(expected);
}

bool PointCloud::sample(const scan::ScanSample& s) {
  if (s.index % every_ != 0) return true;
  const double topography = inverse_ ? s.inverse : s.topography;
  if (!std::isfinite(s.deflection) || !std::isfinite(topography)) return true;
  x_.push_back(s.radius * std::cos(s.angle));
  y_.push_back(s.radius * std::sin(s.angle));
  a_.push_back(s.deflection);
  b_.push_back(topography);
  return true;
}

std::size_t PointCloud::stage(const std::string& path, io::OutputSet& set) {
  const std::size_t n = x_.size();
  std::vector<scan::XyzChannel> channels{{"Deflection", "m", std::move(a_)},
                                         {recorded_ ? "Tilt-free deflection" : "Topography", "m", std::move(b_)}};
  set.add(path, scan::format_gxyzf(scan::XyzField(std::move(x_), std::move(y_), std::move(channels), "m")));
  return n;
}

namespace {
constexpr const char* image_channels[] = {"deflection", "topography", "topography_lagged", "topography_inverse",
                                          "truth", "tilt_free"};  // every scan's names
}

std::vector<std::string> stage_images(const std::string& prefix, const std::vector<NamedImage>& images,
                                      io::OutputSet& set) {
  // each image's preview (levelling, grey levels, PNG compression: the costly part) is encoded on its own thread,
  // two at a time, while this one packs the GSF files; the files are staged (written to their temporaries and
  // synced to disk) one after the other, in order, on threads of their own, at most two behind the packing. The
  // same bytes; at most two previews and two files' contents waiting in memory (the futures wait in their
  // destructors if an error unwinds)
  constexpr std::size_t kPreviewsInFlight = 2, kWritesInFlight = 1;
  std::vector<std::future<std::string>> previews(images.size());
  const auto start_preview = [&](std::size_t k) {
    if (k >= images.size()) return;
    previews[k] = std::async(std::launch::async, [&image = images[k]] {
      const scan::HeightMap& shown =
          image.level_preview && image.map->valid_count() >= 3 ? scan::level(*image.map) : *image.map;
      return scan::format_png16(scan::to_grey16(shown));
    });
  };
  std::deque<std::shared_future<void>> writes;
  const auto stage = [&](const std::string& path, std::string content) {
    for (; writes.size() >= kWritesInFlight; writes.pop_front()) writes.front().get();
    std::shared_future<void> previous = writes.empty() ? std::shared_future<void>() : writes.back();
    writes.push_back(std::async(std::launch::async, [&set, previous, path, content = std::move(content)] {
                       if (previous.valid()) previous.get();  // in order (and not after a failed one)
                       set.add(path, content);
                     }).share());
  };
  for (std::size_t k = 0; k < kPreviewsInFlight; ++k) start_preview(k);
  std::vector<std::string> written;
  for (std::size_t k = 0; k < images.size(); ++k) {
    const NamedImage& image = images[k];
    const std::string gsf = prefix + "_" + image.name + ".gsf", png = prefix + "_" + image.name + ".png";
    try {
      stage(gsf, scan::format_gsf(*image.map, image.title));
      written.push_back(gsf);
      if (image.map->has_mask()) {
        stage(scan::gsf_mask_path(gsf), scan::format_gsf_mask(*image.map, image.title));
        written.push_back(scan::gsf_mask_path(gsf));
      }
      stage(png, previews[k].get());
      written.push_back(png);
    } catch (const InvalidParameter& e) {  // a value the file format cannot hold: name the file and the image
      throw InputError(fmt::format("cannot write the {} image '{}': {}", image.name, gsf, e.what()));
    }
    start_preview(k + kPreviewsInFlight);
  }
  for (; !writes.empty(); writes.pop_front()) writes.front().get();
  return written;
}

std::vector<io::WrittenPath> image_paths(const std::string& prefix) {
  std::vector<io::WrittenPath> paths;
  for (const char* name : image_channels) {
    const std::string gsf = prefix + "_" + name + ".gsf";
    paths.push_back({gsf});
    paths.push_back({scan::gsf_mask_path(gsf)});
    paths.push_back({prefix + "_" + name + ".png"});
  }
  return paths;
}

}  // namespace afmkit::cli
