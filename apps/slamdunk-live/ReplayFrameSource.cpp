#include "ReplayFrameSource.h"

#include <mrpt/system/datetime.h>

#include <filesystem>
#include <stdexcept>
#include <thread>

namespace slamdunk::live {

ReplayFrameSource::ReplayFrameSource(std::string rawlogPath, double speed)
    : path_(std::move(rawlogPath)), speed_(speed) {
  if (!(speed_ > 0)) throw std::runtime_error("replay speed must be > 0");
}

void ReplayFrameSource::open() {
  if (!std::filesystem::is_regular_file(path_))
    throw std::runtime_error("replay rawlog '" + path_ + "' does not exist");
  reader_ = std::make_unique<RawlogReader>(path_);
}

mrpt::obs::CObservation3DRangeScan::Ptr ReplayFrameSource::next(const std::atomic<bool>& stop) {
  if (stop) return nullptr;
  auto obs = reader_->next();
  if (!obs) {
    if (reader_->entriesRead() > 0 && !started_)
      throw std::runtime_error("rawlog '" + path_ + "' has no CObservation3DRangeScan (" +
                               std::to_string(reader_->otherObservationsSkipped()) +
                               " other observations)");
    return nullptr;
  }
  // Decoding is part of "grabbing": a camera also hands over decoded images.
  obs->load();
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
  return "replay of '" + path_ + "' at " + speed + "x speed";
}

}  // namespace slamdunk::live
