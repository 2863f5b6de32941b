#include "afmkit/io/progress.hpp"

#include <cstdio>

#include <fmt/format.h>

namespace afmkit::io {

namespace {
/// The innermost ProgressSink alive on this thread (nullptr: standard error). Per thread, so that commands run at
/// the same time from several Python threads each keep their own.
thread_local const ProgressSink* current_sink = nullptr;
}  // namespace

ProgressSink::ProgressSink(ProgressLines lines) : lines_(std::move(lines)), previous_(current_sink) {
  current_sink = this;
}

ProgressSink::~ProgressSink() { current_sink = previous_; }

void message_line(const std::string& line) {
  if (current_sink != nullptr && current_sink->lines_) current_sink->lines_(line);
  else std::fprintf(stderr, "%s\n", line.c_str());
}

Progress::Progress(std::string label, long total, bool enabled, double interval_seconds)
    : label_(std::move(label)), total_(total), enabled_(enabled), interval_(interval_seconds) {
  if (current_sink != nullptr) lines_ = current_sink->lines_;
  start_ = last_ = std::chrono::steady_clock::now();
}

void Progress::print(const std::string& line) {
  if (lines_) lines_(line);
  else std::fprintf(stderr, "%s\n", line.c_str());
}

void Progress::advance(long n) {
  long done = done_.fetch_add(n) + n;
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  // The clock is read under the lock: read before it, a thread that waited could see a `now` older than the last
  // line's and drop its own line (interval 0: a line per advance, as promised).
  auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_).count() < interval_) return;
  last_ = now;
  print(fmt::format("{}: {}/{} ({:.0f}%)", label_, done, total_,
                    total_ > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total_) : 100.0));
}

void Progress::finish() {
  if (!enabled_) return;
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (secs < interval_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  print(fmt::format("{}: done, {} items in {:.2f} s", label_, done_.load(), secs));
}

}  // namespace afmkit::io
