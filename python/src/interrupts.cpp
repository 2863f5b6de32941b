// SignalPoll (interrupts.hpp): Python's signal handlers polled from a computation that runs without the GIL.
#include "interrupts.hpp"

#include <atomic>
#include <chrono>
#include <thread>

namespace py = pybind11;

namespace afmkit::python {

struct SignalPoll::State {
  std::thread::id owner = std::this_thread::get_id();
  std::chrono::steady_clock::time_point next = std::chrono::steady_clock::now();
  PyObject* type = nullptr;  // the exception a signal handler raised (owned references)
  PyObject* value = nullptr;
  PyObject* traceback = nullptr;

  bool poll() {
    if (std::this_thread::get_id() != owner) return false;  // only the calling thread runs Python's handlers
    const auto now = std::chrono::steady_clock::now();
    if (now < next) return false;
    next = now + std::chrono::milliseconds(50);
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return false;
    PyErr_Fetch(&type, &value, &traceback);
    return true;
  }
};

SignalPoll::SignalPoll()
    : state_(std::make_shared<State>()), cancellation_([s = state_] { return s->poll(); }) {}

bool SignalPoll::hold(py::error_already_set& e) {
  if (!e.matches(PyExc_KeyboardInterrupt) && !e.matches(PyExc_SystemExit)) return false;
  if (!state_->type) {
    e.restore();
    PyErr_Fetch(&state_->type, &state_->value, &state_->traceback);
  }
  cancellation_.request();
  return true;
}

void SignalPoll::raise() {
  if (state_->type) {
    PyErr_Restore(state_->type, state_->value, state_->traceback);
    state_->type = state_->value = state_->traceback = nullptr;
    throw py::error_already_set();
  }
  PyErr_SetNone(PyExc_KeyboardInterrupt);  // stopped by a request without a Python exception: still an interrupt
  throw py::error_already_set();
}

}  // namespace afmkit::python
