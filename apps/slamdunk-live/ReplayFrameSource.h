#pragma once
// Plays a rawlog of CObservation3DRangeScan at the pace of its timestamps (times a speed
// factor), so the live pipeline can be exercised and measured without a camera.

#include "FrameSource.h"

#include <slamdunk/core/RawlogReader.h>

#include <chrono>

namespace slamdunk::live {

class ReplayFrameSource : public FrameSource {
 public:
  /// speed: 1 = real time, 2 = twice as fast, ...; must be > 0.
  ReplayFrameSource(std::string rawlogPath, double speed);

  void open() override;
  mrpt::obs::CObservation3DRangeScan::Ptr next(const std::atomic<bool>& stop) override;
  std::string describe() const override;

 private:
  using Clock = std::chrono::steady_clock;
  std::string path_;
  double speed_;
  std::unique_ptr<RawlogReader> reader_;
  bool started_ = false;
  Clock::time_point wallStart_;  ///< when the first frame was handed out
  double firstStamp_ = 0;        ///< its timestamp (s)
};

}  // namespace slamdunk::live
