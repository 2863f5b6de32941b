#pragma once
// Runs a ScanObserver on a second thread: the simulation (the caller's thread) hands it the samples in batches, so
// the imaging and the per-turn metrics of one batch overlap the simulation of the next (virtual_scan.cpp).
//
// The observer sees every sample, in order, on one thread (not the caller's): it must not share unsynchronised
// state with the caller while the scan runs. When it returns false (stop) or throws, the caller's sample() returns
// false from then on (a batch or so later than a direct observer would stop: the scan's sample count then includes
// those, the observer never sees them); finish() waits for the thread and rethrows the observer's exception.
// Memory: at most four batches of `batch` samples (88 bytes each; 1.4 MB at the default 4096).
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "afmkit/scan/spiral_scan.hpp"

namespace afmkit::scan {

class ObserverThread final : public ScanObserver {
 public:
  explicit ObserverThread(ScanObserver& inner, std::size_t batch = 4096);
  ~ObserverThread() override;  // stops and joins the thread (an exception it threw is dropped: call finish())
  ObserverThread(const ObserverThread&) = delete;
  ObserverThread& operator=(const ObserverThread&) = delete;

  bool sample(const ScanSample& s) override;
  /// Hands over the last partial batch, waits until the observer has seen every sample, rethrows its exception.
  /// Returns whether the observer asked to stop. Idempotent.
  bool finish();

 private:
  void hand_over();
  void work();

  ScanObserver& inner_;
  std::size_t batch_;
  std::vector<ScanSample> filling_;           // the caller's batch
  std::vector<std::vector<ScanSample>> queue_;  // batches handed over, oldest first (at most 2)
  std::vector<std::vector<ScanSample>> spare_;  // emptied batches, for reuse
  std::mutex mutex_;
  std::condition_variable changed_;
  bool closing_ = false, stopped_ = false, finished_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace afmkit::scan
