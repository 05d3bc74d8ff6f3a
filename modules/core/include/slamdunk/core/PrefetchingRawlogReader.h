#pragma once
// Reads and decodes the next range scans of a rawlog on a thread of its own, so that loading
// (external PNGs, depth matrices) overlaps the processing of the frame before: offline, the
// whole-app rate is the tracking rate, not tracking plus decoding.

#include <slamdunk/core/RawlogReader.h>

#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

namespace slamdunk {

class PrefetchingRawlogReader {
 public:
  /// Opens the rawlog (throws like RawlogReader) and starts reading up to `depth` scans ahead.
  /// The reading thread keeps the process's CPU priority: the consumer waits for it whenever
  /// it is behind, so a lower priority would hold the consumer back on a busy machine.
  explicit PrefetchingRawlogReader(const std::string& path, size_t depth = 4);
  ~PrefetchingRawlogReader();  ///< stops the reading thread
  PrefetchingRawlogReader(const PrefetchingRawlogReader&) = delete;
  PrefetchingRawlogReader& operator=(const PrefetchingRawlogReader&) = delete;

  /// The next range scan with its images loaded, in file order; nullptr at the end. Rethrows,
  /// at the scan where it happened, an error reading the file or loading the images.
  mrpt::obs::CObservation3DRangeScan::Ptr next();

  /// Counts as of the scans handed out so far (the reader may be ahead).
  size_t entriesRead() const;
  size_t otherObservationsSkipped() const;
  const std::string& path() const { return reader_.path(); }

 private:
  struct Item {
    mrpt::obs::CObservation3DRangeScan::Ptr scan;  ///< nullptr: the end, or `error`
    std::exception_ptr error;
    size_t entriesRead = 0, skipped = 0;
  };
  void readLoop();

  RawlogReader reader_;
  const size_t depth_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> ready_;
  bool stopping_ = false;
  size_t entriesRead_ = 0, skipped_ = 0;  ///< of the last item handed out
  std::thread thread_;
};

}  // namespace slamdunk
