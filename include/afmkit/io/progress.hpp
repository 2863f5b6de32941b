#pragma once
// Progress for long runs: prints "label: k/n (p%)" to stderr at most every `interval` seconds.
// Thread-safe `advance()`; silent when `enabled` is false.
//
// Where the lines go (and a command's warnings, message_line): standard error, unless a ProgressSink is alive on the
// thread that makes the Progress; then
// to its function (the Python module sends them to Python's sys.stderr, which Jupyter shows under the running
// cell, rather than to the process's file descriptor 2, which a notebook does not show everywhere).
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>

namespace afmkit::io {

/// Receives one progress line (no trailing newline); called from whichever thread advances the Progress.
using ProgressLines = std::function<void(const std::string& line)>;

/// While it lives, every Progress made on this thread sends its lines to `lines` (nested sinks: the innermost;
/// a Progress keeps the sink it was made with). Scoped to one thread and one call: a front end other than the
/// command line (the Python module) sets one around a command it runs.
class ProgressSink {
 public:
  explicit ProgressSink(ProgressLines lines);
  ~ProgressSink();
  ProgressSink(const ProgressSink&) = delete;
  ProgressSink& operator=(const ProgressSink&) = delete;

 private:
  ProgressLines lines_;
  const ProgressSink* previous_;
  friend class Progress;
  friend void message_line(const std::string& line);
};

/// Writes `line` (a command's warning; no trailing newline) where this thread's progress lines go: the innermost
/// ProgressSink alive on it, else standard error.
void message_line(const std::string& line);

class Progress {
 public:
  Progress(std::string label, long total, bool enabled = true, double interval_seconds = 1.0);
  void advance(long n = 1);
  void finish();

 private:
  void print(const std::string& line);
  std::string label_;
  long total_;
  bool enabled_;
  double interval_;
  ProgressLines lines_;  ///< empty: standard error
  std::atomic<long> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace afmkit::io
