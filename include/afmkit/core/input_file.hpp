#pragma once
// Opening a file a user names as input (a force curve, a recorded spiral, a sample image, a list of separations, a
// TOML file): one place that refuses what is not a regular file before anything reads it (a FIFO would block
// forever, /dev/zero would read until memory runs out, a directory is not "a file without a header line") and that
// bounds what is read by the memory this run may use (docs/development.md#memory-and-sizes).
//
//   const std::string text = files::read_input_file(path, "force_curve");          // whole file, bounded
//   auto in = files::open_input_file(path, "recorded");                            // streamed, never blocks
// Both throw afmkit::InputError naming `what` and the path: "force_curve 'x' is a directory, not a file".
#include <cstdint>
#include <istream>
#include <memory>
#include <string>

namespace afmkit::files {

/// The bytes a whole-file reader may read now: a quarter of memory::available_bytes() (MemAvailable capped by
/// ulimit -v and AFMKIT_MEMORY_LIMIT), since parsing holds the text and what it becomes at once.
std::uintmax_t input_size_limit();

/// The content of the regular file `path`. InputError naming `what` and the path when it does not exist, is not a
/// regular file (directory, FIFO, device, socket: refused without blocking), cannot be read, or is larger than
/// `max_bytes` or than input_size_limit() (the message says which limit and how to raise the second).
std::string read_input_file(const std::string& path, const std::string& what,
                            std::uintmax_t max_bytes = UINTMAX_MAX);

/// A stream over the regular file `path` for readers that stream (bounded memory): refused as read_input_file
/// refuses, without blocking on a FIFO.
std::unique_ptr<std::istream> open_input_file(const std::string& path, const std::string& what);

}  // namespace afmkit::files
