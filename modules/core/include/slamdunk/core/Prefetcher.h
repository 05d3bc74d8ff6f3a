#pragma once
// Produces a sequence of items on a thread of its own, a few items ahead of the consumer, so
// that producing the next item (decoding a rawlog entry, extracting a frame's features)
// overlaps the consumer's work on the one before. Items come out in production order: what the
// consumer sees does not depend on timing.

#include <slamdunk/core/WorkerThread.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

namespace slamdunk {

template <class T>
class Prefetcher {
 public:
  /// Returns the next item, or std::nullopt at the end. An exception it throws ends the
  /// sequence there.
  using Produce = std::function<std::optional<T>()>;

  /// Starts producing, up to `depth` items ahead of next(). The thread keeps the process's CPU
  /// priority: the consumer waits for it whenever it is behind, so a lower priority would hold
  /// the consumer back on a busy machine.
  Prefetcher(Produce produce, size_t depth)
      : produce_(std::move(produce)), depth_(std::max<size_t>(depth, 1)) {
    thread_ = std::thread([this] { produceLoop(); });
  }
  ~Prefetcher() { stopWorker(thread_, mutex_, changed_, stopping_); }  ///< stops producing
  Prefetcher(const Prefetcher&) = delete;
  Prefetcher& operator=(const Prefetcher&) = delete;

  /// The next item in production order; std::nullopt at the end. Rethrows, in its place, the
  /// exception that ended the sequence. The end (or the exception) stays: asking again gives
  /// the same answer.
  std::optional<T> next() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !ready_.empty(); });
    Slot& front = ready_.front();
    const std::exception_ptr error = front.error;
    std::optional<T> item;
    if (front.item) {
      item = std::move(front.item);
      ready_.pop_front();
    }
    lock.unlock();
    changed_.notify_all();
    if (error) std::rethrow_exception(error);
    return item;
  }

 private:
  struct Slot {
    std::optional<T> item;  ///< unset: the end, or `error`
    std::exception_ptr error;
  };

  void produceLoop() {
    for (;;) {
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return stopping_ || ready_.size() < depth_; });
        if (stopping_) return;
      }
      Slot slot;
      try {
        slot.item = produce_();
      } catch (...) {
        slot.item.reset();
        slot.error = std::current_exception();
      }
      const bool last = !slot.item;
      {
        std::lock_guard lock(mutex_);
        ready_.push_back(std::move(slot));
      }
      changed_.notify_all();
      if (last) return;  // the end or an error: nothing follows
    }
  }

  Produce produce_;
  const size_t depth_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Slot> ready_;
  bool stopping_ = false;
  std::thread thread_;  ///< last: started once everything it uses is
};

}  // namespace slamdunk
