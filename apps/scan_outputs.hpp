#pragma once
// Outputs of `afmkit scan` shared by the simulated and the recorded scan: the optional time series (CSV), the
// optional point cloud (GXYZF) and the images (GSF + mask, PNG preview). Every file is written atomically.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "afmkit/io/output.hpp"
#include "afmkit/scan/gxyzf.hpp"
#include "afmkit/scan/height_map.hpp"
#include "afmkit/scan/spiral_scan.hpp"

namespace afmkit::cli {

/// Streams every `every`-th sample to a CSV (columns given; `cells` turns a sample into the row).
class SeriesWriter final : public scan::ScanObserver {
 public:
  SeriesWriter(const std::string& path, long every, bool recorded);
  bool sample(const scan::ScanSample& s) override;
  void commit(const nlohmann::json& sidecar) { writer_.commit(sidecar); }
  std::size_t rows() const { return writer_.size(); }

 private:
  io::TableWriter writer_;
  long every_;
  bool recorded_;
};

/// Collects every `every`-th sample's (x, y) and channels for a GXYZF point cloud.
class PointCloud final : public scan::ScanObserver {
 public:
  PointCloud(long every, bool recorded, std::size_t expected);
  bool sample(const scan::ScanSample& s) override;
  /// Writes the GXYZF file; returns the number of points.
  std::size_t write(const std::string& path);

 private:
  long every_;
  bool recorded_;
  std::vector<double> x_, y_, a_, b_;
};

/// An image to write: <prefix>_<name>.gsf (+ _mask.gsf when it has invalid pixels) and <prefix>_<name>.png (the
/// preview: levelled by its least-squares plane when `level_preview`, so a tilted height map shows its features).
struct NamedImage {
  std::string name;   // file name part, e.g. "topography"
  std::string title;  // Gwyddion channel title
  const scan::HeightMap* map;
  bool level_preview = false;
};
/// Writes the images; returns the paths written.
std::vector<std::string> write_images(const std::string& prefix, const std::vector<NamedImage>& images);

}  // namespace afmkit::cli
