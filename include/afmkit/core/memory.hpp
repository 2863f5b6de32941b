#pragma once
// A request's memory, checked before any work: a size option that would need more memory than the machine can
// give is bad input (InvalidParameter, CLI exit 2) with the amount needed and available, never std::bad_alloc.
#include <cstddef>
#include <string>

namespace afmkit::memory {

/// Bytes of memory available to a new allocation now (MemAvailable of /proc/meminfo, or the physical memory
/// when that is unreadable), capped by the address-space limit (ulimit -v) and by the environment variable
/// AFMKIT_MEMORY_LIMIT (bytes, or with a suffix K, M, G, T; e.g. "2G" on a shared node) when they are set.
/// A malformed AFMKIT_MEMORY_LIMIT -> InvalidParameter("AFMKIT_MEMORY_LIMIT").
std::size_t available_bytes();

/// Throws InvalidParameter(parameter, …) when `bytes` (what a request of `value` for `parameter` needs, e.g.
/// rows × bytes per row) exceeds `fraction` of available_bytes(); the message names the parameter, its value,
/// the memory needed and the largest value that fits. `bytes_per_unit` (> 0) converts between the two.
void require_fits(const std::string& parameter, double value, double bytes_per_unit, double fraction = 0.5);

/// The same for a request that grows with the square of `side` (a side × side image): it needs
/// `bytes_per_pixel` · side² + `other_bytes` (what the rest of the request holds at the same time); the message
/// names the largest side that fits.
void require_fits_square(const std::string& parameter, double side, double bytes_per_pixel, double other_bytes = 0.0,
                         double fraction = 0.5);

}  // namespace afmkit::memory
