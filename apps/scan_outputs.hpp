#pragma once
// Outputs of `afmkit scan` shared by the simulated and the recorded scan: the optional time series (CSV), the
// optional point cloud (GXYZF) and the images (GSF + mask, PNG preview). Every file is staged into the command's
// output set and committed with the per-turn table: all of them or none (io::OutputSet).
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
  void stage(const nlohmann::json& sidecar, io::OutputSet& set) { writer_.stage(sidecar, set); }
  std::size_t rows() const { return writer_.size(); }

 private:
  io::TableWriter writer_;
  long every_;
  bool recorded_;
};

/// Collects every `every`-th sample's (x, y) and channels for a GXYZF point cloud.
class PointCloud final : public scan::ScanObserver {
 public:
  /// `inverse`: the topography channel is the inverse reconstruction (else the lagged one, or the recorded tilt-free
  /// signal).
  PointCloud(long every, bool recorded, std::size_t expected, bool inverse = false);
  bool sample(const scan::ScanSample& s) override;
  /// Stages the GXYZF file for `path` into `set`; returns the number of points.
  std::size_t stage(const std::string& path, io::OutputSet& set);

 private:
  long every_;
  bool recorded_;
  bool inverse_;
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
/// Stages the images into `set`; returns their paths.
std::vector<std::string> stage_images(const std::string& prefix, const std::vector<NamedImage>& images,
                                      io::OutputSet& set);
/// Every file stage_images may write for `prefix` (any channel of the simulated or recorded scan), for the check
/// that no output replaces an input (io::ParamSet::writes).
std::vector<io::WrittenPath> image_paths(const std::string& prefix);

}  // namespace afmkit::cli
