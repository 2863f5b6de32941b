// Parameters of `afmkit scan` (scan_params.hpp).
#include "scan_params.hpp"

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"
#include "afmkit/scan/ascii_matrix.hpp"
#include "afmkit/scan/gsf.hpp"
#include "afmkit/scan/png16.hpp"
#include "afmkit/scan/sample_generators.hpp"
#include "control_params.hpp"

namespace afmkit::cli {

namespace {
constexpr double kDegree = std::numbers::pi / 180.0;

std::string lower_extension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

// Every sample height, scaled, lies in [−kMaxHeight, kMaxHeight] m (docs/scan.md#samples): far beyond any AFM
// topography, and far enough inside the double range that the scan's sums and squares stay finite.
constexpr double kMaxHeight = 1.0;

/// The index of the largest |z| (the first non-finite one if any).
std::size_t largest_at(const std::vector<double>& z) {
  std::size_t at = 0;
  for (std::size_t k = 0; k < z.size(); ++k) {
    if (!std::isfinite(z[k])) return k;
    if (std::abs(z[k]) > std::abs(z[at])) at = k;
  }
  return at;
}

/// Refuses file values `raw` (row-major, `columns` per row) whose heights raw · scale leave [−1, 1] m.
void require_file_heights(const std::vector<double>& raw, long columns, double scale, const std::string& path,
                          const char* what) {
  if (raw.empty()) return;
  const std::size_t at = largest_at(raw);
  const double v = raw[at], height = v * scale;
  if (std::abs(height) <= kMaxHeight) return;
  const auto c = static_cast<std::size_t>(columns);
  throw InvalidParameter(
      "sample_z_scale",
      fmt::format("sample_z_scale = {} m is out of range for {}: its {} {} at row {}, column {} (from 1) gives the "
                  "height {} m; every sample height must lie in [-{}, {}] m: sample_z_scale must be <= {} m for this "
                  "file",
                  scale, path, what, v, at / c + 1, at % c + 1, height, kMaxHeight, kMaxHeight,
                  std::abs(v) > 0 && std::isfinite(kMaxHeight / std::abs(v)) ? kMaxHeight / std::abs(v) : 0.0));
}

/// Refuses a generated or GSF map whose heights leave [−1, 1] m, naming `key` (what sets them).
void require_map_heights(const std::vector<double>& z, long columns, const std::string& key, const std::string& what) {
  if (z.empty()) return;
  const std::size_t at = largest_at(z);
  if (std::abs(z[at]) <= kMaxHeight) return;
  const auto c = static_cast<std::size_t>(columns);
  throw InvalidParameter(key, fmt::format("{}: the height {} m at row {}, column {} (from 1) is out of range: every "
                                          "sample height must lie in [-{}, {}] m",
                                          what, z[at], at / c + 1, at % c + 1, kMaxHeight, kMaxHeight));
}

// A map read from a file, re-centred on the spindle axis (its centre at (0, 0)).
scan::HeightMap centred(const scan::Grid& g, std::vector<double> z) {
  scan::Grid c = g;
  c.x_offset = -0.5 * g.x_size;
  c.y_offset = -0.5 * g.y_size;
  return scan::HeightMap(c, std::move(z), "m");
}

scan::HeightMap sample_from_file(const io::ParamSet& p) {
  const std::string path = p.text("sample_file");
  if (path.empty())
    throw InvalidParameter("sample_file", "sample = file needs sample_file (a .gsf, .png or ASCII matrix file)");
  const std::string ext = lower_extension(path);
  const double size = p.real("sample_size"), scale = p.real("sample_z_scale");
  if (ext == ".gsf") {
    scan::GsfField f = scan::read_gsf(path);
    if (f.map.z_unit() != "m")
      throw InputError(fmt::format("{}: ZUnits = '{}': a sample height map must be in metres (ZUnits = m)", path,
                                   f.map.z_unit()));
    if (f.map.valid_count() != f.map.size())
      throw InputError(fmt::format("{}: {} of {} pixels are not finite: a sample height map must be complete", path,
                                   f.map.size() - f.map.valid_count(), f.map.size()));
    const scan::Grid g = f.map.grid();
    require_map_heights(f.map.data(), g.x_resolution, "sample_file", path);
    return centred(g, std::move(f.map).data());
  }
  if (!p.was_set("sample_size"))
    throw InvalidParameter("sample_size", fmt::format("{} holds no physical size: give sample_size [m] (the width of "
                                                      "the image; pixels are square)", path));
  std::vector<double> z;
  long columns = 0, rows = 0;
  if (ext == ".png") {
    if (!p.was_set("sample_z_scale"))
      throw InvalidParameter("sample_z_scale", fmt::format("{} holds grey levels: give sample_z_scale [m] = the "
                                                           "height of grey level 65535", path));
    const scan::Grey16 img = scan::read_png16(path);
    columns = img.width;
    rows = img.height;
    if (!(scale <= kMaxHeight))
      throw InvalidParameter("sample_z_scale", fmt::format("sample_z_scale = {} m is out of range for {} (the height "
                                                           "of grey level 65535): every sample height must lie in "
                                                           "[-{}, {}] m: must be in (0, {}] m",
                                                           scale, path, kMaxHeight, kMaxHeight, kMaxHeight));
    z.reserve(img.pixels.size());
    for (std::uint16_t g : img.pixels) z.push_back(scale * (static_cast<double>(g) / 65535.0));
  } else {
    scan::AsciiMatrix m = scan::read_ascii_matrix(path);
    columns = m.columns;
    rows = m.rows;
    require_file_heights(m.values, m.columns, scale, path, "value");
    z = std::move(m.values);
    for (double& v : z) v *= scale;
  }
  const double dx = size / static_cast<double>(columns);
  return centred(scan::Grid{columns, rows, size, dx * static_cast<double>(rows), 0.0, 0.0}, std::move(z));
}

}  // namespace

void add_sample_params(io::ParamSet& p) {
  const auto positive = io::Range::positive();
  const auto non_negative = io::Range::non_negative();
  p.group("Sample")
      .text("sample", "grating", "sample topography: a built-in generator or a file",
            {"grating", "steps", "particles", "rough", "flat", "file"})
      .file("sample_file", "", "height map for sample = file: .gsf (metres), .png (16-bit grey) or ASCII matrix")
      .real("sample_size", 0.0, "sample width (generators: square side; png/ASCII files: image width)",
            non_negative)
      .unit("m")
      .default_text("generators: scan 2.04 x end_radius, tapping image the larger side of the scan")
      .real("sample_z_scale", 1.0, "height per file unit: ASCII values x scale; png: height of grey 65535", positive)
      .unit("m")
      .integer("sample_resolution", 2048, "pixels per side of a generated sample", 16, 16384)
      .integer("sample_seed", 1, "random seed of the particles and rough generators", 0, 4294967295L)
      .real("grating_period", 800e-6, "grating period", positive)
      .unit("m")
      .real("grating_height", 50e-9, "grating line height", io::Range::any())
      .unit("m")
      .real("grating_duty", 0.5, "fraction of a period at the line height", io::Range::closed(0.0, 1.0))
      .unit("dimensionless")
      .real("steps_width", 500e-6, "width of one terrace", positive)
      .unit("m")
      .real("steps_height", 20e-9, "height of one step", io::Range::any())
      .unit("m")
      .integer("particles_count", 60, "number of spherical particles", 1, 1000000)
      .real("particles_radius", 100e-6, "particle radius", positive)
      .unit("m")
      .real("rough_rms", 20e-9, "RMS height of the rough surface", positive)
      .unit("m")
      .real("rough_correlation_length", 100e-6, "correlation length of the rough surface", positive)
      .unit("m")
      .real("tilt_angle", 0.05, "tilt of the sample normal from the spindle axis, in [0, 90)", non_negative)
      .unit("deg")
      .real("tilt_azimuth", 0.0, "direction of the tilt in the sample plane", io::Range::any())
      .unit("deg");
}

void add_scan_params(io::ParamSet& p) {
  const auto positive = io::Range::positive();
  const auto non_negative = io::Range::non_negative();
  add_sample_params(p);
  p.group("Spiral")
      .real("spindle_frequency", 50.0, "spindle rotation frequency f_rot (Omega = 2 pi f_rot)", positive)
      .unit("Hz")
      .real("start_radius", 0.0, "radius where the scan starts", non_negative)
      .unit("m")
      .real("end_radius", 4e-3, "radius where the scan stops (> start_radius)", positive)
      .unit("m")
      .real("radial_speed", 150e-6, "outward speed of the tip; pitch = radial_speed / spindle_frequency", positive)
      .unit("m/s")
      .real("sample_rate", 300e3, "samples per second (>= 16 per turn)", positive)
      .unit("Hz")
      .group("Plant and actuator (seed 2, eq. 1)")
      .real("bandwidth", 2.0 * std::numbers::pi * 1000.0, "plant rate gamma of the deflection signal", positive)
      .unit("rad/s")
      .default_text("2 pi x 1000")
      .real("delay", 1e-3, "actuator delay tau (below one spindle period)", non_negative)
      .unit("s")
      .real("delay_drift", 0.0, "amplitude of the slow delay drift, tau(t) = delay + delay_drift sin(2 pi t / P)",
            io::Range::closed(0.0, 1e308))
      .unit("s")
      .real("delay_drift_period", 10.0, "period P of the delay drift", positive)
      .unit("s")
      .real("gain_error", 0.0, "actuator sensitivity error: actual = (1 + gain_error) x calibrated (> -1)",
            io::Range::any())
      .unit("dimensionless")
      .group("Detector")
      .real("detector_range", 2e-6, "linear range of the deflection detector, +-detector_range", positive)
      .unit("m")
      .real("detector_noise", 0.0, "RMS of white Gaussian detector noise", non_negative)
      .unit("m")
      .integer("noise_seed", 1, "seed of the detector noise", 0, 4294967295L)
      .group("Controller (seed 2, eqs. 15, 6, 20)")
      .text("control", "on", "the harmonic-rejection controller in the loop", {"on", "off"});
  add_harmonics_param(p, 10000, "oscillators N of the bank (N x spindle_frequency below sample_rate / 2)");
  add_coupling_alpha(p);  // as the control commands declare them (control_params.hpp)
  add_coupling_beta(p);
  p.real("gain", 0.0, "controller gain K (0: the design rule K = bandwidth)", non_negative)
      .unit("rad/s")
      .follows("bandwidth")  // recorded as the gain used
      .group("Reconstruction (docs/scan.md#reconstruction)")
      .text("reconstruction", "inverse",
            "what the topography image shows: inverse (the plant's first-order lag removed, seed 2 eq. 1) or lagged "
            "(deflection + actuator displacement); the other is written as <prefix>_topography_<other>",
            {"inverse", "lagged"})
      .real("reconstruction_bandwidth", 0.0,
            "plant rate gamma the reconstruction and the actuator model assume (0: the true bandwidth)", non_negative)
      .unit("rad/s")
      .follows("bandwidth")  // recorded as the rate used
      .text("inverse", "wiener",
            "how the inverse treats detector noise: wiener (the exact inverse followed by the Wiener low-pass along "
            "the turn, from detector_noise, the plant and the sample's prior; the exact inverse when detector_noise "
            "= 0) or exact",
            {"wiener", "exact"})
      .real("prior_increment", 0.0,
            "RMS height change between consecutive samples the Wiener prior assumes (0: from the sample map along "
            "the spiral)", non_negative)
      .unit("m");
}

namespace {
// Peak bytes per pixel (docs/development.md#memory-and-sizes), rounded up: the images of a simulated scan (the
// imager's four channels — deflection, both reconstructions, the true heights at the samples — with its sorted
// pixel radii, then those images and the ground truth with their masks, levelling and the GSF/PNG encoding of one
// image at a time; measured 73.4 bytes from the peak resident memory at 1024² and 2048² pixels), of a recorded one
// (two images: at most that), and a generated sample map (measured 8 bytes, the rough generator's spectrum 18.4
// bytes).
constexpr double kSimulatedImageBytes = 80.0;
constexpr double kRecordedImageBytes = 64.0;
constexpr double kSampleBytes = 24.0;
// A sample file held in memory: its bytes, then the decoded values and the height map (GSF: 4 bytes a value in
// the file, 8 + 8 in memory; ASCII: at least 2 bytes a value), per byte of the file.
constexpr double kFileBytesPerByte = 6.0;
// A PNG's pixels: 2 bytes raw + 2 decoded + 8 scaled + 8 in the map.
constexpr double kPngBytesPerPixel = 24.0;

/// Width · height of a PNG from its IHDR chunk (0 if the file is not a readable PNG: the reader reports that).
double png_pixels(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<unsigned char, 24> h{};
  if (!in.read(reinterpret_cast<char*>(h.data()), h.size())) return 0.0;
  auto be32 = [&](std::size_t at) {
    return static_cast<double>((std::uint32_t{h[at]} << 24) | (std::uint32_t{h[at + 1]} << 16) |
                               (std::uint32_t{h[at + 2]} << 8) | std::uint32_t{h[at + 3]});
  };
  if (h[12] != 'I' || h[13] != 'H' || h[14] != 'D' || h[15] != 'R') return 0.0;
  return be32(16) * be32(20);
}

/// The bytes the sample map needs (0 for a recorded scan); InvalidParameter when the sample alone does not fit.
double sample_bytes(const io::ParamSet& p) {
  const double usable = 0.5 * static_cast<double>(memory::available_bytes());
  const double gib = 1024.0 * 1024.0 * 1024.0;
  if (p.text("sample") != "file") {
    const auto n = static_cast<double>(p.integer("sample_resolution"));
    memory::require_fits_square("sample_resolution", n, kSampleBytes);
    return n * n * kSampleBytes;
  }
  const std::string path = p.text("sample_file");
  std::error_code error;
  if (path.empty() || !std::filesystem::is_regular_file(path, error)) return 0.0;  // the reader reports it
  const double size = static_cast<double>(std::filesystem::file_size(path, error));
  if (error) return 0.0;
  const double needed = lower_extension(path) == ".png" ? png_pixels(path) * kPngBytesPerPixel
                                                        : size * kFileBytesPerByte;
  if (!(needed <= usable))
    throw InvalidParameter("sample_file",
                           fmt::format("sample_file = {} ({:.3g} MiB) needs about {:.2f} GiB of memory as a height map, "
                                       "more than the {:.2f} GiB usable now (50 % of MemAvailable, capped by ulimit -v "
                                       "and AFMKIT_MEMORY_LIMIT): use a smaller file",
                                       path, size / (1024.0 * 1024.0), needed / gib, usable / gib));
  return needed;
}
}  // namespace

double require_sample_memory(const io::ParamSet& p) { return sample_bytes(p); }

void require_scan_memory(const io::ParamSet& p, bool recorded) {
  const double sample = recorded ? 0.0 : sample_bytes(p);
  memory::require_fits_square("image_resolution", static_cast<double>(p.integer("image_resolution")),
                              recorded ? kRecordedImageBytes : kSimulatedImageBytes, sample);
}

const std::vector<std::string>& simulation_only_keys() {
  static const std::vector<std::string> keys{
      "sample", "sample_file", "sample_size", "sample_z_scale", "sample_resolution", "sample_seed", "grating_period",
      "grating_height", "grating_duty", "steps_width", "steps_height", "particles_count", "particles_radius",
      "rough_rms", "rough_correlation_length", "tilt_angle", "tilt_azimuth", "spindle_frequency", "start_radius",
      "end_radius", "radial_speed", "sample_rate", "bandwidth", "delay", "delay_drift", "delay_drift_period",
      "gain_error", "detector_range", "detector_noise", "noise_seed", "control", "gain", "reconstruction",
      "reconstruction_bandwidth", "inverse", "prior_increment"};
  return keys;
}

void record_only_what_applies(io::ParamSet& p) {
  for (const std::string& key : simulation_only_keys()) p.applies_when(key, "recorded", {""});
  record_only_sample_keys_that_apply(p);
}

void record_only_sample_keys_that_apply(io::ParamSet& p) {
  p.applies_when("sample_file", "sample", {"file"})
      .applies_when("sample_z_scale", "sample", {"file"})
      .applies_when("sample_resolution", "sample", {"grating", "steps", "particles", "rough", "flat"})
      .applies_when("sample_seed", "sample", {"particles", "rough"});
  for (const char* key : {"grating_period", "grating_height", "grating_duty"}) p.applies_when(key, "sample", {"grating"});
  for (const char* key : {"steps_width", "steps_height"}) p.applies_when(key, "sample", {"steps"});
  for (const char* key : {"particles_count", "particles_radius"}) p.applies_when(key, "sample", {"particles"});
  for (const char* key : {"rough_rms", "rough_correlation_length"}) p.applies_when(key, "sample", {"rough"});
}

scan::InstrumentSpec instrument_from(const io::ParamSet& p) {
  scan::InstrumentSpec s;
  s.spiral.spindle_frequency = p.real("spindle_frequency");
  s.spiral.start_radius = p.real("start_radius");
  s.spiral.end_radius = p.real("end_radius");
  s.spiral.radial_speed = p.real("radial_speed");
  s.spiral.sample_rate = p.real("sample_rate");
  s.plant.bandwidth = p.real("bandwidth");
  s.plant.delay = p.real("delay");
  s.plant.delay_drift = p.real("delay_drift");
  s.plant.delay_drift_period = p.real("delay_drift_period");
  s.plant.gain_error = p.real("gain_error");
  s.detector.range = p.real("detector_range");
  s.detector.noise = p.real("detector_noise");
  s.detector.seed = static_cast<std::uint64_t>(p.integer("noise_seed"));
  s.controller.enabled = p.text("control") == "on";
  s.controller.harmonics = static_cast<int>(p.integer("harmonics"));
  s.controller.alpha = p.real("alpha");
  s.controller.beta = p.real("beta");
  s.controller.gain = p.real("gain");
  s.reconstruction.method =
      p.text("reconstruction") == "lagged" ? scan::Reconstruction::lagged : scan::Reconstruction::inverse;
  // not given: 0, the true bandwidth (the record shows that value: follows("bandwidth"))
  s.reconstruction.assumed_bandwidth = p.was_set("reconstruction_bandwidth") ? p.real("reconstruction_bandwidth") : 0.0;
  s.reconstruction.inverse_filter =
      p.text("inverse") == "exact" ? scan::InverseFilter::exact : scan::InverseFilter::wiener;
  s.reconstruction.prior_increment = p.real("prior_increment");
  s.validate();
  return s;
}

double generated_sample_size(const io::ParamSet& p) {
  return p.was_set("sample_size") ? p.real("sample_size") : 2.04 * p.real("end_radius");
}

scan::Surface surface_from(const io::ParamSet& p) {
  const double tilt_angle = p.real("tilt_angle");
  if (!(tilt_angle < 90.0))
    throw InvalidParameter("tilt_angle", fmt::format("tilt_angle = {} deg is out of range: must be in [0, 90) deg",
                                                     tilt_angle));
  const scan::Tilt tilt(tilt_angle * kDegree, p.real("tilt_azimuth") * kDegree);
  // the tilt adds r·tan ψ to the heights along the spiral: at end_radius it must stay within the sample heights'
  // bound (docs/scan.md#samples)
  const double end_radius = p.real("end_radius"), tilt_height = end_radius * std::tan(tilt.angle);
  if (!(tilt_height <= kMaxHeight))
    throw InvalidParameter(
        "tilt_angle",
        fmt::format("tilt_angle = {} deg with end_radius = {} m tilts the sample by {:.6g} m at the end of the spiral "
                    "(end_radius x tan(tilt_angle)); every height must lie in [-{}, {}] m: tilt_angle must be <= {:.6g} "
                    "deg for this end_radius (or end_radius <= {:.6g} m for this tilt_angle)",
                    tilt_angle, end_radius, tilt_height, kMaxHeight, kMaxHeight,
                    std::atan(kMaxHeight / end_radius) / kDegree, kMaxHeight / std::tan(tilt.angle)));
  return scan::Surface(sample_map_from(p, generated_sample_size(p)), tilt);
}

scan::HeightMap sample_map_from(const io::ParamSet& p, double generated_size) {
  const std::string kind = p.text("sample");
  if (kind == "file") return sample_from_file(p);
  if (p.was_set("sample_file"))
    throw InvalidParameter("sample_file", fmt::format("sample_file is given but sample = {}: set sample = file to "
                                                      "scan the file, or leave sample_file out", kind));

  const double size = generated_size;
  if (!(size > 0.0))
    throw InvalidParameter("sample_size", fmt::format("sample_size = {} m is out of range: must be > 0", size));
  const long n = p.integer("sample_resolution");
  const scan::Grid grid{n, n, size, size, -0.5 * size, -0.5 * size};
  const auto seed = static_cast<unsigned>(p.integer("sample_seed"));
  scan::HeightMap map = [&] {
    if (kind == "grating")
      return scan::grating(grid, {p.real("grating_period"), p.real("grating_height"), p.real("grating_duty"), 0.0});
    if (kind == "steps") return scan::steps(grid, {p.real("steps_width"), p.real("steps_height"), 0.0});
    if (kind == "particles")
      return scan::particles(grid, {static_cast<int>(p.integer("particles_count")), p.real("particles_radius"), seed});
    if (kind == "rough") return scan::rough(grid, {p.real("rough_rms"), p.real("rough_correlation_length"), seed});
    return scan::flat(grid);
  }();
  const std::string key = kind == "grating" ? "grating_height"
                          : kind == "steps" ? "steps_height"
                          : kind == "particles" ? "particles_radius"
                          : kind == "rough" ? "rough_rms"
                                            : "sample";
  require_map_heights(map.data(), n, key, fmt::format("sample = {} with {} = {} m", kind, key,
                                                      kind == "flat" ? 0.0 : p.real(key)));
  return map;
}

}  // namespace afmkit::cli
