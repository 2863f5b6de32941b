#pragma once
// Exceptions and OpenMP: an exception must not leave a parallel region (std::terminate). Loop bodies run through
// ExceptionCollector::run, which keeps the first exception; rethrow() after the loop raises it on the calling
// thread, where the command boundary turns it into a message and an exit status.
#include <exception>
#include <mutex>

namespace afmkit {

class ExceptionCollector {
 public:
  /// Runs body(); an exception it throws is kept (the first one) instead of propagating.
  template <class Body>
  void run(Body&& body) noexcept {
    try {
      body();
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
    }
  }
  bool failed() const noexcept { return static_cast<bool>(error_); }
  /// Raises the kept exception, if any (call after the parallel loop).
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
};

}  // namespace afmkit
