#pragma once
// A cancellation hook for tests (core/cancellation.hpp): asks to stop at its `after`-th call, counting every call.
#include <atomic>

#include "afmkit/core/cancellation.hpp"

namespace afmkit_test {

struct CountingStop {
  std::atomic<long> calls{0};
  long after;
  explicit CountingStop(long a) : after(a) {}
  afmkit::Cancellation cancellation() {
    return afmkit::Cancellation([this] { return ++calls >= after; });
  }
};

}  // namespace afmkit_test
