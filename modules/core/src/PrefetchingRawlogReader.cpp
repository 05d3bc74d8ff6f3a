#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/PrefetchingRawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/WorkerThread.h>

#include <algorithm>
#include <stdexcept>

namespace slamdunk {

PrefetchingRawlogReader::PrefetchingRawlogReader(const std::string& path, size_t depth)
    : reader_(path), depth_(std::max<size_t>(depth, 1)) {
  thread_ = std::thread([this] { readLoop(); });
}

PrefetchingRawlogReader::~PrefetchingRawlogReader() {
  stopWorker(thread_, mutex_, changed_, stopping_);
}

void PrefetchingRawlogReader::readLoop() {
  // At the process's priority, not lower: the consumer waits for this thread whenever it is
  // behind, so at nice 19 other work on the machine held the consumer back (slamdunk-rawlog on
  // 7-Scenes beside two busy loops: 9-25 frames/s against 47), and an idle machine gained
  // nothing from it.
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || ready_.size() < depth_; });
      if (stopping_) return;
    }
    Item item;
    try {
      item.scan = reader_.next();
      if (item.scan) {
        try {
          loadExternalImages(*item.scan);
        } catch (const std::exception& e) {
          // Externally stored images: MRPT's error names the image, not the rawlog.
          throw std::runtime_error(
              "rawlog '" + reader_.path() + "', entry " +
              std::to_string(reader_.entriesRead() - 1) +
              ": cannot load its external images: " + summarizeError(e.what()));
        }
      }
    } catch (...) {
      item.scan.reset();
      item.error = std::current_exception();
    }
    item.entriesRead = reader_.entriesRead();
    item.skipped = reader_.otherObservationsSkipped();
    const bool last = !item.scan;
    {
      std::lock_guard lock(mutex_);
      ready_.push_back(std::move(item));
    }
    changed_.notify_all();
    if (last) return;  // the end or an error: nothing follows
  }
}

mrpt::obs::CObservation3DRangeScan::Ptr PrefetchingRawlogReader::next() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !ready_.empty(); });
  Item item = ready_.front();
  // The end (or the error) stays queued: asking again gives the same answer.
  if (item.scan) ready_.pop_front();
  entriesRead_ = item.entriesRead;
  skipped_ = item.skipped;
  lock.unlock();
  changed_.notify_all();
  if (item.error) std::rethrow_exception(item.error);
  return item.scan;
}

size_t PrefetchingRawlogReader::entriesRead() const {
  std::lock_guard lock(mutex_);
  return entriesRead_;
}

size_t PrefetchingRawlogReader::otherObservationsSkipped() const {
  std::lock_guard lock(mutex_);
  return skipped_;
}

}  // namespace slamdunk
