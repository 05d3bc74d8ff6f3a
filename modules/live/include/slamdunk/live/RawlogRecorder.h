#pragma once
// Records the received frames to a rawlog while the pipeline runs. Compressing and writing
// happen in the recorder's own thread so a slow disk never delays grabbing; the file is
// streamed to a temporary name and renamed over the target only by finish().

#include <slamdunk/core/AtomicOutput.h>

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

namespace slamdunk::live {

class RawlogRecorder {
 public:
  /// Opens the temporary file; throws std::runtime_error if it cannot be created.
  /// At most `maxBacklog` frames wait to be written; beyond that new ones are skipped (counted).
  explicit RawlogRecorder(const std::string& path, size_t maxBacklog = 60);
  ~RawlogRecorder();  ///< without finish(): stops and removes the temporary file

  /// Queues a self-contained copy of the frame (its images embedded, not external references,
  /// so the recording replays without the source's image folder). Call from one thread.
  void add(const mrpt::obs::CObservation3DRangeScan& frame);
  /// Writes what is queued, closes and renames the file. Throws on a write error.
  void finish();

  size_t written() const { return written_; }
  size_t skipped() const { return skipped_; }

 private:
  void writerLoop();
  void stopWriter();

  AtomicOutput output_;
  mrpt::io::CFileGZOutputStream file_;
  const size_t maxBacklog_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<mrpt::obs::CObservation3DRangeScan::Ptr> backlog_;
  std::atomic<size_t> written_{0}, skipped_{0};
  bool stopping_ = false;
  std::string error_;
  std::thread writer_;
};

}  // namespace slamdunk::live
