#pragma once
// One guard for every commit of outputs (internal to io): while files are moved into place — a set of tables and
// sidecars (output.cpp: OutputSet::commit), a Zarr store (zarr_store.cpp: ZarrStoreWriter::commit) — SIGINT,
// SIGTERM and SIGHUP are blocked in the committing thread and only noted by the handler in the others (output.hpp:
// remove_temporaries_on_signal), so that the commit completes; the noted signal is delivered when the last guard
// ends. A commit is all or none even when a signal comes (issue 24 §3).
#include <signal.h>

namespace afmkit::io::detail {

class SignalsHeld {
 public:
  SignalsHeld();
  ~SignalsHeld();
  SignalsHeld(const SignalsHeld&) = delete;
  SignalsHeld& operator=(const SignalsHeld&) = delete;

 private:
  sigset_t old_;
};

/// For the signal handler (async-signal-safe): while a SignalsHeld is alive in any thread, notes `signal_number` to
/// be delivered when the last one ends and returns true; else false (the handler acts on it).
bool defer_signal(int signal_number) noexcept;

}  // namespace afmkit::io::detail
