#pragma once
// Ctrl-C in Python during a long computation: the computation runs with the GIL released and a Cancellation
// (core/cancellation.hpp) whose hook, on the thread that called from Python (the main thread runs the signal
// handlers), takes the GIL at most every 50 ms and calls PyErr_CheckSignals. When a handler raises (SIGINT:
// KeyboardInterrupt), the computation stops at its next check and the Python exception is raised to the caller.
#include <memory>

#include <pybind11/pybind11.h>

#include "afmkit/core/cancellation.hpp"

namespace afmkit::python {

class SignalPoll {
 public:
  /// Call with the GIL held, on the thread that will run the computation.
  SignalPoll();
  /// The Cancellation to give the computation (copies share this poll).
  Cancellation cancellation() const { return cancellation_; }
  /// With the GIL held, from Python code the computation called back (a progress line written to sys.stderr): a
  /// KeyboardInterrupt or SystemExit raised there — a signal handler runs inside any Python code of the main thread,
  /// and has then consumed its signal — is kept as the stop request (the first one wins): the computation stops at
  /// its next check and run() raises it. Returns whether `e` was such a request (else the caller handles it).
  bool hold(pybind11::error_already_set& e);
  /// Runs `body` (with the GIL released); a Cancelled from it raises the Python exception that stopped it.
  template <class Body>
  void run(Body&& body) {
    try {
      pybind11::gil_scoped_release release;
      body();
    } catch (const Cancelled&) {
      raise();
    }
  }

 private:
  struct State;
  [[noreturn]] void raise();
  std::shared_ptr<State> state_;
  Cancellation cancellation_;
};

}  // namespace afmkit::python
