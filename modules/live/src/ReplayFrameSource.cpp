#include <slamdunk/live/ReplayFrameSource.h>

#include <mrpt/system/datetime.h>

#include <filesystem>
#include <stdexcept>
#include <thread>

namespace slamdunk::live {

ReplayFrameSource::ReplayFrameSource(std::string rawlogPath, double speed, int loops,
                                     size_t readAhead)
    : path_(std::move(rawlogPath)), speed_(speed), loops_(loops), readAhead_(readAhead) {
  if (!(speed_ > 0)) throw std::runtime_error("replay speed must be > 0");
  if (loops_ < 0) throw std::runtime_error("replay loops must be >= 0 (0 = until stopped)");
  if (readAhead_ < 1) throw std::runtime_error("replay read-ahead must be >= 1 frame");
}

std::unique_ptr<PrefetchingRawlogReader> ReplayFrameSource::openReader() const {
  return std::make_unique<PrefetchingRawlogReader>(path_, readAhead_);
}

void ReplayFrameSource::open() {
  if (!std::filesystem::is_regular_file(path_))
    throw std::runtime_error("replay rawlog '" + path_ + "' does not exist");
  reader_ = openReader();
}

mrpt::obs::CObservation3DRangeScan::Ptr ReplayFrameSource::nextScan() {
  auto obs = reader_->next();
  const bool lastLap = loops_ > 0 && lap_ + 1 >= loops_;
  if (!obs && started_ && !lastLap) {
    // The next lap follows this one by the mean frame interval of the recording.
    const double firstLapSpan = lapLastStamp_ - firstStamp_;
    const double interval = lapFrames_ > 1 ? firstLapSpan / (lapFrames_ - 1) : 1.0 / 30;
    lapOffset_ += firstLapSpan + interval;
    ++lap_;
    lapFrames_ = 0;
    reader_ = openReader();
    obs = reader_->next();
  }
  if (!obs) return nullptr;
  ++lapFrames_;
  if (lap_ == 0) {
    lapLastStamp_ = mrpt::Clock::toDouble(obs->timestamp);
  } else {
    obs->timestamp = mrpt::Clock::fromDouble(mrpt::Clock::toDouble(obs->timestamp) + lapOffset_);
  }
  return obs;
}

mrpt::obs::CObservation3DRangeScan::Ptr ReplayFrameSource::next(const std::atomic<bool>& stop) {
  if (stop) return nullptr;
  auto obs = nextScan();
  if (!obs) {
    if (reader_->entriesRead() > 0 && !started_)
      throw std::runtime_error("rawlog '" + path_ + "' has no CObservation3DRangeScan (" +
                               std::to_string(reader_->otherObservationsSkipped()) +
                               " other observations)");
    return nullptr;
  }
  const double stamp = mrpt::Clock::toDouble(obs->timestamp);
  if (!started_) {
    started_ = true;
    wallStart_ = Clock::now();
    firstStamp_ = stamp;
    return obs;
  }
  // Due time from the recording's own clock; a frame already late is handed out at once.
  const auto due = wallStart_ + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>((stamp - firstStamp_) / speed_));
  // Sleep in short slices so Ctrl-C is honoured even on a recording with a long gap.
  while (!stop && Clock::now() < due)
    std::this_thread::sleep_for(
        std::min<Clock::duration>(due - Clock::now(), std::chrono::milliseconds(50)));
  return stop ? nullptr : obs;
}

std::string ReplayFrameSource::describe() const {
  char speed[32];
  std::snprintf(speed, sizeof(speed), "%g", speed_);
  const std::string laps = loops_ == 0   ? ", looped until stopped"
                           : loops_ == 1 ? ""
                                         : ", " + std::to_string(loops_) + " laps";
  return "replay of '" + path_ + "' at " + speed + "x speed" + laps;
}

}  // namespace slamdunk::live
