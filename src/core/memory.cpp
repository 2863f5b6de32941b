#include "afmkit/core/memory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include "afmkit/core/error.hpp"

namespace afmkit::memory {

namespace {
/// AFMKIT_MEMORY_LIMIT: bytes, or a number with the suffix K, M, G or T (powers of 1024); 0 when unset.
std::size_t limit_from_environment() {
  const char* text = std::getenv("AFMKIT_MEMORY_LIMIT");
  if (!text || !*text) return 0;
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  double scale = 1.0;
  const std::string suffix(end);
  if (suffix == "K" || suffix == "k") scale = 1024.0;
  else if (suffix == "M") scale = 1024.0 * 1024.0;
  else if (suffix == "G") scale = 1024.0 * 1024.0 * 1024.0;
  else if (suffix == "T") scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else if (!suffix.empty()) scale = -1.0;
  if (end == text || !(value > 0) || !(scale > 0) || !std::isfinite(value * scale) || value * scale > 1e18)
    throw InvalidParameter("AFMKIT_MEMORY_LIMIT",
                           fmt::format("AFMKIT_MEMORY_LIMIT = '{}' is out of range: must be a positive number of "
                                       "bytes, optionally with the suffix K, M, G or T",
                                       text));
  return static_cast<std::size_t>(value * scale);
}
}  // namespace

std::size_t available_bytes() {
  std::size_t bytes = 0;
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);) {
    std::istringstream in(line);
    std::string key;
    std::size_t kib = 0;
    if (in >> key >> kib && key == "MemAvailable:") {
      bytes = kib * 1024;
      break;
    }
  }
  if (bytes == 0) {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0) bytes = static_cast<std::size_t>(pages) * static_cast<std::size_t>(page);
  }
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    bytes = bytes == 0 ? limit.rlim_cur : std::min<std::size_t>(bytes, limit.rlim_cur);
  if (const std::size_t user = limit_from_environment()) bytes = bytes == 0 ? user : std::min(bytes, user);
  return bytes;
}

void require_fits(const std::string& parameter, double value, double bytes_per_unit, double fraction) {
  const double needed = value * bytes_per_unit;
  const double usable = fraction * static_cast<double>(available_bytes());
  if (!(needed <= usable)) {
    const double gib = 1024.0 * 1024.0 * 1024.0;
    throw InvalidParameter(
        parameter, fmt::format("{} = {} needs about {:.2f} GiB of memory, more than the {:.2f} GiB usable now ({:.0f} % "
                               "of MemAvailable, capped by ulimit -v and AFMKIT_MEMORY_LIMIT): must be <= {:.0f}",
                               parameter, value, needed / gib, usable / gib, 100.0 * fraction,
                               std::floor(usable / bytes_per_unit)));
  }
}

void require_fits_square(const std::string& parameter, double side, double bytes_per_pixel, double other_bytes,
                         double fraction) {
  const double needed = side * side * bytes_per_pixel + other_bytes;
  const double usable = fraction * static_cast<double>(available_bytes());
  if (!(needed <= usable)) {
    const double gib = 1024.0 * 1024.0 * 1024.0;
    const double largest = usable > other_bytes ? std::floor(std::sqrt((usable - other_bytes) / bytes_per_pixel)) : 0.0;
    throw InvalidParameter(
        parameter, fmt::format("{} = {} needs about {:.2f} GiB of memory ({} x {} pixels{}), more than the {:.2f} GiB "
                               "usable now ({:.0f} % of MemAvailable, capped by ulimit -v and AFMKIT_MEMORY_LIMIT): "
                               "must be <= {:.0f}",
                               parameter, side, needed / gib, side, side,
                               other_bytes > 0 ? fmt::format(", with {:.3g} GiB for the rest", other_bytes / gib) : "",
                               usable / gib, 100.0 * fraction, largest));
  }
}

}  // namespace afmkit::memory
