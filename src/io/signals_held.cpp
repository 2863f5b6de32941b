// The commit guard shared by the output writers (signals_held.hpp).
#include "signals_held.hpp"

#include <atomic>
#include <csignal>

namespace afmkit::io::detail {

namespace {
// Process-wide by nature (a signal is): how many commits run, and a signal noted meanwhile. Lock-free atomics:
// the handler reads and writes them.
std::atomic<int> commits_running{0};
std::atomic<int> pending_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
}  // namespace

SignalsHeld::SignalsHeld() {
  sigset_t set;
  sigemptyset(&set);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&set, s);
  pthread_sigmask(SIG_BLOCK, &set, &old_);
  ++commits_running;
}

SignalsHeld::~SignalsHeld() {
  if (--commits_running == 0)
    if (const int s = pending_signal.exchange(0)) std::raise(s);  // blocked here: delivered by the line below
  pthread_sigmask(SIG_SETMASK, &old_, nullptr);
}

bool defer_signal(int signal_number) noexcept {
  if (commits_running.load() == 0) return false;
  pending_signal.store(signal_number);
  return true;
}

}  // namespace afmkit::io::detail
