// A ScanObserver on a second thread, fed in batches (observer_thread.hpp).
#include "afmkit/scan/observer_thread.hpp"

#include <utility>

namespace afmkit::scan {

ObserverThread::ObserverThread(ScanObserver& inner, std::size_t batch) : inner_(inner), batch_(batch > 0 ? batch : 1) {
  filling_.reserve(batch_);
  thread_ = std::thread([this] { work(); });
}

ObserverThread::~ObserverThread() {
  {
    std::lock_guard lock(mutex_);
    closing_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool ObserverThread::sample(const ScanSample& s) {
  filling_.push_back(s);
  if (filling_.size() < batch_) return true;
  hand_over();
  std::lock_guard lock(mutex_);
  return !stopped_;
}

void ObserverThread::hand_over() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queue_.size() < 2 || stopped_; });  // at most three batches alive
  if (stopped_) {
    filling_.clear();
    return;
  }
  queue_.push_back(std::move(filling_));
  if (!spare_.empty()) {
    filling_ = std::move(spare_.back());
    spare_.pop_back();
  } else {
    filling_ = {};
    filling_.reserve(batch_);
  }
  lock.unlock();
  changed_.notify_all();
}

void ObserverThread::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return !queue_.empty() || closing_; });
    if (queue_.empty()) return;  // closing, nothing left
    std::vector<ScanSample> batch = std::move(queue_.front());
    queue_.erase(queue_.begin());
    const bool skip = stopped_;
    lock.unlock();
    bool go = !skip;
    std::exception_ptr error;
    if (go) {
      try {
        for (const ScanSample& s : batch)
          if (!inner_.sample(s)) {
            go = false;
            break;
          }
      } catch (...) {
        error = std::current_exception();
        go = false;
      }
    }
    batch.clear();
    lock.lock();
    if (!go && !skip) stopped_ = true;
    if (error && !error_) error_ = error;
    spare_.push_back(std::move(batch));
    changed_.notify_all();
  }
}

bool ObserverThread::finish() {
  if (!finished_) {
    finished_ = true;
    if (!filling_.empty()) hand_over();
    {
      std::lock_guard lock(mutex_);
      closing_ = true;
    }
    changed_.notify_all();
    thread_.join();
    if (error_) std::rethrow_exception(error_);
  }
  return stopped_;
}

}  // namespace afmkit::scan
