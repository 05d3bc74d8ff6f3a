#pragma once
// One status line on stderr about every `period` seconds while the pipeline runs: frame rates
// over the last period, tracking state, keyframes, dropped and lost frames; and one line per
// checkpoint written.

#include <slamdunk/live/CheckpointWriter.h>
#include <slamdunk/live/LivePipeline.h>

#include <optional>

namespace slamdunk::live {

class StatusPrinter {
 public:
  /// period <= 0 disables the output.
  explicit StatusPrinter(double period);
  /// Call often (e.g. every 100 ms); prints when a period has passed.
  void tick(const LiveCounters& now);
  /// Prints a line for each checkpoint written since the last call.
  void checkpoints(const std::optional<CheckpointFigures>& figures);

 private:
  using Clock = std::chrono::steady_clock;
  double period_;
  Clock::time_point start_, last_;
  LiveCounters previous_;
  size_t checkpointsShown_ = 0;
  bool checkpointErrorShown_ = false;
};

}  // namespace slamdunk::live
