#include <slamdunk/core/WorkerThread.h>
#include <slamdunk/live/RawlogRecorder.h>

#include <slamdunk/core/RgbdFrame.h>

#include <mrpt/serialization/CArchive.h>

#include <opencv2/core.hpp>

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace slamdunk::live {

RawlogRecorder::RawlogRecorder(const std::string& path, size_t maxBacklog)
    : output_(path), maxBacklog_(maxBacklog) {
  // Level 1: the fastest gzip level; live frames arrive at 30 Hz on a small machine.
  if (!file_.open(output_.tempPath(), 1))
    throw std::runtime_error("cannot create the recording '" + output_.tempPath() + "'");
  writer_ = std::thread([this] { writerLoop(); });
}

RawlogRecorder::~RawlogRecorder() { stopWriter(); }

void RawlogRecorder::add(const mrpt::obs::CObservation3DRangeScan& frame) {
  {
    std::lock_guard lock(mutex_);
    if (!error_.empty()) return;  // the recording failed: finish() reports it
    if (backlog_.size() >= maxBacklog_) {
      ++skipped_;
      return;
    }
  }
  // The tracker reads the original concurrently, and a frame replayed from a rawlog with
  // external images must be embedded to make the recording self-contained.
  auto copy = selfContainedCopy(frame);
  {
    std::lock_guard lock(mutex_);
    backlog_.push_back(std::move(copy));
  }
  ready_.notify_one();
}

void RawlogRecorder::writerLoop() {
  auto archive = mrpt::serialization::archiveFrom(file_);
  std::unique_lock lock(mutex_);
  for (;;) {
    ready_.wait(lock, [&] { return !backlog_.empty() || stopping_; });
    if (backlog_.empty()) return;  // stopping and everything written
    auto frame = std::move(backlog_.front());
    backlog_.pop_front();
    lock.unlock();
    std::string error;
    try {
      archive << *frame;
    } catch (const std::exception& e) {
      error = e.what();
    }
    lock.lock();
    if (!error.empty()) {
      error_ = error;
      backlog_.clear();
      // A full disk: give its space back at once, or the partial recording would leave no room
      // for the trajectory and map written when the session ends.
      file_.close();
      std::error_code ec;
      std::filesystem::remove(output_.tempPath(), ec);
      return;
    }
    ++written_;
  }
}

void RawlogRecorder::stopWriter() { stopWorker(writer_, mutex_, ready_, stopping_); }

void RawlogRecorder::finish() {
  stopWriter();
  {
    std::lock_guard lock(mutex_);
    if (!error_.empty())
      throw std::runtime_error("recording '" + output_.targetPath() + "' failed: " + error_);
  }
  const uint64_t bytes = file_.getPosition();
  file_.close();
  requireCompleteGzip(output_.tempPath(), bytes, output_.targetPath());
  output_.commit();
}

}  // namespace slamdunk::live
