#pragma once
// Gwyddion as a real client of the files afmkit writes: runs gwyddion-thumbnailer (Debian package `gwyddion`,
// installed by scripts/bootstrap.sh) on a file and reports what it did. The thumbnailer loads the file through
// Gwyddion's own file modules (gsffile.c, gxyzffile.c, …) and renders the first image channel with the default
// grey gradient, so a PNG written means Gwyddion parsed the file, and its pixels show what Gwyddion read.
//
// Behaviour found with gwyddion-thumbnailer 2.62 (Debian 12):
//   command line   gwyddion-thumbnailer gnome2 MAX-SIZE INPUT OUTPUT.png    (also `kde4 MAX-SIZE INPUT` to stdout,
//                  `tms MAX-SIZE INPUT` to ~/.thumbnails); `-c ID` picks a channel.
//   headless       needs no X display (it only calls gtk_parse_args); it reads ~/.gwyddion/settings (default
//                  palette) and ~/.gwyddion/modules, so render() runs it with HOME set to an empty scratch folder
//                  and LC_ALL=C (the RealSize text uses the locale's decimal point).
//   success        exit 0; an RGB PNG of the channel, never scaled up (scaled down to fit MAX-SIZE), row 0 at
//                  the top, grey level clamp(255 · (z − lo) / (hi − lo), 0, 255) where [lo, hi] is Gwyddion's
//                  "auto" range (the full range minus sparse histogram tails: gwy_app_get_channel_thumbnail turns
//                  RANGE_FULL into RANGE_AUTO); tEXt chunks Thumb::Image::Width / Height (the channel's XRes /
//                  YRes) and Thumb::X-Gwyddion::RealSize ("1.00×2.00 µm", Latin-1 in the file).
//   failure        exit 1, no output file, one line on stderr:
//                    "gwyddion-thumbnailer: Aborting. write_thumbnail failed with: <reason>." where <reason> is
//                    "File contains no previewable data"         the file loaded, but holds no image channel
//                                                                (a GXYZF point cloud: XYZ data only)
//                    "Expected data size calculated from file headers is 864 bytes, but the real size is 860
//                     bytes"                                     a GSF whose data size does not match XRes·YRes
//                    "Data size 1192 is not a multiple of point size 24"     a truncated GXYZF
//                    "No module can load this file type"         no format recognised (bad magic line)
//                  or "gwyddion-thumbnailer: Aborting. stat failed with: No such file or directory".
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <png.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace gwyddion_client {

inline constexpr const char* thumbnailer_name = "gwyddion-thumbnailer";
inline constexpr const char* missing_thumbnailer_message =
    "gwyddion-thumbnailer not found (neither $AFMKIT_GWYDDION_THUMBNAILER nor on $PATH): the Gwyddion client tests "
    "need it; scripts/bootstrap.sh installs it (Debian package `gwyddion`: apt-get install gwyddion)";
/// The reason the thumbnailer gives for a file that loaded but holds no image channel (e.g. XYZ data).
inline constexpr const char* no_previewable_data = "File contains no previewable data";
/// What precedes every reason the thumbnailer gives for a file it could not load or render.
inline constexpr const char* load_failure_prefix = "write_thumbnail failed with: ";

/// The first executable file named `name` in the ':'-separated folder list `search_path`; "" when none.
inline std::string find_on_path(const std::string& name, const std::string& search_path) {
  std::size_t start = 0;
  while (start <= search_path.size()) {
    std::size_t end = search_path.find(':', start);
    if (end == std::string::npos) end = search_path.size();
    const std::string folder = search_path.substr(start, end - start);
    start = end + 1;
    if (folder.empty()) continue;
    const std::string candidate = (std::filesystem::path(folder) / name).string();
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
      return candidate;
  }
  return "";
}

/// The thumbnailer: $AFMKIT_GWYDDION_THUMBNAILER when set (a path), else gwyddion-thumbnailer on $PATH; "" when
/// neither exists (callers fail with missing_thumbnailer_message: the tests never skip silently).
inline std::string find_thumbnailer() {
  if (const char* forced = std::getenv("AFMKIT_GWYDDION_THUMBNAILER"); forced && *forced)
    return ::access(forced, X_OK) == 0 ? std::string(forced) : std::string();
  const char* path = std::getenv("PATH");
  return find_on_path(thumbnailer_name, path ? path : "/usr/local/bin:/usr/bin:/bin");
}

inline constexpr unsigned char png_signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

/// A decoded PNG: 8-bit RGB pixels (row-major from the top row, 3 bytes per pixel) and its text chunks (tEXt
/// values converted from Latin-1 to UTF-8; uncompressed iTXt as they are).
struct Png {
  long width = 0;
  long height = 0;
  std::vector<std::uint8_t> rgb;
  std::vector<std::pair<std::string, std::string>> text;
  std::string error;  ///< "" when decoded; else why not (libpng's message)

  std::uint8_t red(long i, long j) const { return rgb[static_cast<std::size_t>(3 * (j * width + i))]; }
  std::uint8_t green(long i, long j) const { return rgb[static_cast<std::size_t>(3 * (j * width + i) + 1)]; }
  std::uint8_t blue(long i, long j) const { return rgb[static_cast<std::size_t>(3 * (j * width + i) + 2)]; }
  /// The value of text chunk `key`, "" when absent.
  std::string text_value(std::string_view key) const {
    for (const auto& [k, v] : text)
      if (k == key) return v;
    return "";
  }
};

inline std::string latin1_to_utf8(std::string_view in) {
  std::string out;
  for (char ch : in) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x80) {
      out.push_back(ch);
    } else {
      out.push_back(static_cast<char>(0xC0 | (c >> 6)));
      out.push_back(static_cast<char>(0x80 | (c & 0x3F)));
    }
  }
  return out;
}

/// Decodes `bytes` (a PNG file): pixels through libpng's simplified API, text chunks by walking the chunk list.
inline Png decode_png(const std::string& bytes) {
  Png png;
  if (bytes.size() < 8 || std::memcmp(bytes.data(), png_signature, 8) != 0) {
    png.error = "not a PNG (bad signature)";
    return png;
  }
  auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(k)]);
    return v;
  };
  for (std::size_t at = 8; at + 12 <= bytes.size();) {
    const std::size_t length = be32(at);
    if (length > bytes.size() - at - 12) break;
    const std::string type = bytes.substr(at + 4, 4);
    const std::string data = bytes.substr(at + 8, length);
    at += 12 + length;
    const std::size_t nul = data.find('\0');
    if (nul == std::string::npos) continue;
    if (type == "tEXt") {
      png.text.emplace_back(data.substr(0, nul), latin1_to_utf8(std::string_view(data).substr(nul + 1)));
    } else if (type == "iTXt" && nul + 2 < data.size() && data[nul + 1] == '\0') {  // uncompressed only
      const std::size_t lang_end = data.find('\0', nul + 3);
      const std::size_t translated_end = lang_end == std::string::npos ? lang_end : data.find('\0', lang_end + 1);
      if (translated_end != std::string::npos) png.text.emplace_back(data.substr(0, nul), data.substr(translated_end + 1));
    }
  }
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) {
    png.error = image.message;
    return png;
  }
  image.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> pixels(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) {
    png.error = image.message;
    png_image_free(&image);
    return png;
  }
  png.width = image.width;
  png.height = image.height;
  png.rgb = std::move(pixels);
  return png;
}

/// What one run of the thumbnailer did.
struct Thumbnail {
  int exit_status = -1;      ///< exit status; -1 when it did not exit (signal, timeout) or could not be started
  std::string error_output;  ///< its standard error
  bool png_written = false;  ///< the output file exists, is not empty and starts with the PNG signature
  Png image;                 ///< the output decoded (when png_written)

  /// Gwyddion loaded the file but found no image channel (XYZ data): the "no previewable data" message.
  bool no_previewable_data() const {
    return error_output.find(std::string(load_failure_prefix) + gwyddion_client::no_previewable_data) !=
           std::string::npos;
  }
  /// The reason after "write_thumbnail failed with: " ("" when there is none).
  std::string failure_reason() const {
    const std::size_t at = error_output.find(load_failure_prefix);
    if (at == std::string::npos) return "";
    std::string reason = error_output.substr(at + std::strlen(load_failure_prefix));
    while (!reason.empty() && (reason.back() == '\n' || reason.back() == '\r')) reason.pop_back();
    return reason;
  }
};

inline std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Runs `thumbnailer gnome2 max_size input <scratch_dir>/<input name>.thumbnail.png` and waits for it (at most
/// `timeout`, then kills it). Environment: PATH as ours, HOME and XDG_* folders in an empty
/// <scratch_dir>/gwyddion_home (no user settings, palette or modules), LC_ALL=C, no DISPLAY. Standard input is
/// /dev/null, standard output is discarded, standard error is captured. `scratch_dir` must exist.
inline Thumbnail render(const std::string& thumbnailer, const std::string& input, const std::string& scratch_dir,
                        int max_size = 256, std::chrono::seconds timeout = std::chrono::seconds(60)) {
  namespace fs = std::filesystem;
  Thumbnail result;
  const fs::path scratch(scratch_dir);
  const fs::path home = scratch / "gwyddion_home";
  fs::create_directories(home);
  const std::string output = (scratch / (fs::path(input).filename().string() + ".thumbnail.png")).string();
  const std::string error_file = (scratch / (fs::path(input).filename().string() + ".thumbnail.stderr")).string();
  fs::remove(output);

  const char* parent_path = std::getenv("PATH");
  std::vector<std::string> environment = {
      "PATH=" + std::string(parent_path ? parent_path : "/usr/local/bin:/usr/bin:/bin"),
      "HOME=" + home.string(),
      "XDG_CONFIG_HOME=" + (home / "config").string(),
      "XDG_DATA_HOME=" + (home / "data").string(),
      "XDG_CACHE_HOME=" + (home / "cache").string(),
      "LC_ALL=C",
  };
  const std::string size_text = std::to_string(max_size);
  std::vector<std::string> arguments = {thumbnailer, "gnome2", size_text, input, output};
  std::vector<char*> argv, envp;
  for (auto& a : arguments) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (auto& e : environment) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, error_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, thumbnailer.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    result.error_output = "cannot start " + thumbnailer + ": " + std::strerror(spawned);
    return result;
  }
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  bool timed_out = false;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0) {
      status = -1;
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);  // the process started above, by its id
      ::waitpid(pid, &status, 0);
      timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  result.error_output = read_all(error_file);
  if (timed_out) result.error_output += "\n(killed after the timeout)";
  result.exit_status = (!timed_out && status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
  std::error_code ec;
  if (fs::is_regular_file(output, ec) && fs::file_size(output, ec) > 0) {
    const std::string bytes = read_all(output);
    result.png_written = bytes.size() >= 8 && std::memcmp(bytes.data(), png_signature, 8) == 0;
    if (result.png_written) result.image = decode_png(bytes);
  }
  return result;
}

}  // namespace gwyddion_client
