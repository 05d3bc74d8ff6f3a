#pragma once
// Finishing a worker thread that sleeps on a condition variable until there is work or it is
// told to stop.

#include <condition_variable>
#include <mutex>
#include <thread>

namespace slamdunk {

/// Sets `stopping` under `mutex` (so the wake-up cannot fall between the worker's check of the
/// flag and its wait), wakes the worker and waits for it to end. Nothing to wait for when the
/// worker never started.
inline void stopWorker(std::thread& worker, std::mutex& mutex, std::condition_variable& wake,
                       bool& stopping) {
  {
    std::lock_guard lock(mutex);
    stopping = true;
  }
  wake.notify_all();
  if (worker.joinable()) worker.join();
}

}  // namespace slamdunk
