#pragma once
// Progress for long runs: prints "label: k/n (p%)" to stderr at most every `interval` seconds.
// Thread-safe `advance()`; silent when `enabled` is false.
#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

namespace afmkit::io {

class Progress {
 public:
  Progress(std::string label, long total, bool enabled = true, double interval_seconds = 1.0);
  void advance(long n = 1);
  void finish();

 private:
  std::string label_;
  long total_;
  bool enabled_;
  double interval_;
  std::atomic<long> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace afmkit::io
