#include "afmkit/io/progress.hpp"

#include <cstdio>

namespace afmkit::io {

Progress::Progress(std::string label, long total, bool enabled, double interval_seconds)
    : label_(std::move(label)), total_(total), enabled_(enabled), interval_(interval_seconds) {
  start_ = last_ = std::chrono::steady_clock::now();
}

void Progress::advance(long n) {
  long done = done_.fetch_add(n) + n;
  if (!enabled_) return;
  auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (std::chrono::duration<double>(now - last_).count() < interval_) return;
  last_ = now;
  std::fprintf(stderr, "%s: %ld/%ld (%.0f%%)\n", label_.c_str(), done, total_,
               total_ > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total_) : 100.0);
}

void Progress::finish() {
  if (!enabled_) return;
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (secs >= interval_) std::fprintf(stderr, "%s: done, %ld items in %.2f s\n", label_.c_str(), done_.load(), secs);
}

}  // namespace afmkit::io
