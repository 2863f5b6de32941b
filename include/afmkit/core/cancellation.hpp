#pragma once
// Cancellation of long computations: a caller-supplied stop request, checked once per point of the loops that can
// run for seconds (control chart and tune, tapping sweep / grid / orbit search / continuation / HB branch scan, the
// virtual scan). The library keeps no global state: a Cancellation travels in the computation's options (copies
// share one request) and is empty — never stops, costs one pointer test per check — unless a front end gives it a
// hook. The Python module gives one that honours Ctrl-C (docs/python.md); the command line keeps its signal
// handling (SIGINT ends the process after removing temporaries, io/output.hpp) and passes none.
//
// check() throws Cancelled once the hook has asked to stop; from then on every check() (from any thread) throws,
// so a parallel loop whose iterations begin with a check drains at once and ExceptionCollector (parallel.hpp)
// rethrows the first Cancelled on the calling thread. Cancelled is neither the user's error (InvalidParameter,
// InputError) nor a numerical failure: front ends report it as an interruption.
#include <atomic>
#include <functional>
#include <memory>
#include <stdexcept>

namespace afmkit {

/// The computation was stopped on request (Cancellation::check).
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("computation interrupted on request") {}
};

class Cancellation {
 public:
  /// Returns true when the computation must stop. Called from any thread that runs a check (also concurrently);
  /// the hook decides how often it does real work (the Python one polls signals at most every 50 ms, on the main
  /// thread only) and must be cheap otherwise.
  using Hook = std::function<bool()>;

  Cancellation() = default;  // never stops
  explicit Cancellation(Hook hook) : state_(std::make_shared<State>(std::move(hook))) {}

  /// Throws Cancelled when a stop has been requested (now or by an earlier check).
  void check() const {
    if (!state_) return;
    if (state_->stopped.load(std::memory_order_relaxed) || (state_->hook && state_->hook())) {
      state_->stopped.store(true, std::memory_order_relaxed);
      throw Cancelled();
    }
  }
  /// Requests a stop without a hook (e.g. from another thread); the next check() throws. No effect when empty.
  void request() const noexcept {
    if (state_) state_->stopped.store(true, std::memory_order_relaxed);
  }
  bool requested() const noexcept { return state_ && state_->stopped.load(std::memory_order_relaxed); }

 private:
  struct State {
    explicit State(Hook h) : hook(std::move(h)) {}
    Hook hook;
    std::atomic<bool> stopped{false};
  };
  std::shared_ptr<State> state_;
};

}  // namespace afmkit
