#pragma once
// Plays a rawlog of CObservation3DRangeScan at the pace of its timestamps (times a speed
// factor), so the live pipeline can be exercised and measured without a camera. It can play the
// recording again and again (soak tests): each lap's timestamps are shifted to follow the last
// lap's, one frame interval later, so time keeps increasing as from a camera.
//
// A camera hands over each frame decoded at its time; a replay must read and decode it from
// files first, and a file read can wait on the disk for hundreds of ms (measured: 434 ms while
// another process wrote and flushed). So frames are read and decoded ahead, on a thread of
// their own, and each is handed out at its due time from what is already in memory.

#include <slamdunk/live/FrameSource.h>

#include <slamdunk/core/PrefetchingRawlogReader.h>

#include <chrono>

namespace slamdunk::live {

class ReplayFrameSource : public FrameSource {
 public:
  /// Frames read and decoded ahead by default: half a second at 30 Hz (a 640x480 RGB-D frame
  /// takes about 2 MB).
  static constexpr size_t kDefaultReadAhead = 15;

  /// speed: 1 = real time, 2 = twice as fast, ...; must be > 0. loops: laps to play, 0 = until
  /// stopped. readAhead >= 1: frames read and decoded ahead of their due time.
  ReplayFrameSource(std::string rawlogPath, double speed, int loops = 1,
                    size_t readAhead = kDefaultReadAhead);

  void open() override;
  mrpt::obs::CObservation3DRangeScan::Ptr next(const std::atomic<bool>& stop) override;
  std::string describe() const override;

 private:
  using Clock = std::chrono::steady_clock;
  /// The next scan of the current lap, starting the next lap at the end of one; nullptr at the
  /// end of the last lap.
  mrpt::obs::CObservation3DRangeScan::Ptr nextScan();
  std::unique_ptr<PrefetchingRawlogReader> openReader() const;

  std::string path_;
  double speed_;
  int loops_;
  size_t readAhead_;
  std::unique_ptr<PrefetchingRawlogReader> reader_;
  bool started_ = false;
  Clock::time_point wallStart_;  ///< when the first frame was handed out
  double firstStamp_ = 0;        ///< its timestamp (s)
  int lap_ = 0;                  ///< 0 = the first
  size_t lapFrames_ = 0;         ///< scans read in the current lap
  double lapLastStamp_ = 0;      ///< the last scan's own stamp in the first lap (s)
  double lapOffset_ = 0;         ///< added to the stamps of the current lap (s)
};

}  // namespace slamdunk::live
