#include "StatusPrinter.h"

#include <cstdio>

namespace slamdunk::live {

StatusPrinter::StatusPrinter(double period)
    : period_(period), start_(Clock::now()), last_(start_) {}

void StatusPrinter::tick(const LiveCounters& now) {
  if (period_ <= 0) return;
  const auto t = Clock::now();
  const double dt = std::chrono::duration<double>(t - last_).count();
  if (dt < period_) return;
  std::fprintf(stderr,
               "[slamdunk-live] %6.1f s | in %5.1f fps | tracking %5.1f fps | %-11s | "
               "keyframes %zu | dropped %zu | lost %zu\n",
               std::chrono::duration<double>(t - start_).count(),
               (now.received - previous_.received) / dt, (now.processed - previous_.processed) / dt,
               !now.processed       ? "waiting"
               : now.lastOutsideMap ? "outside map"
                                    : toString(now.lastStatus),
               now.keyframes, now.dropped, now.lost);
  previous_ = now;
  last_ = t;
}

void StatusPrinter::checkpoints(const std::optional<CheckpointFigures>& figures) {
  if (!figures) return;
  for (; checkpointsShown_ < figures->written; ++checkpointsShown_)
    std::fprintf(stderr,
                 "[slamdunk-live] %6.1f s | checkpoint %zu written in %.0f ms (graph copy %.1f "
                 "ms): %s\n",
                 std::chrono::duration<double>(Clock::now() - start_).count(),
                 checkpointsShown_ + 1, figures->totalMs[checkpointsShown_],
                 figures->snapshotMs[checkpointsShown_], figures->folder.c_str());
  if (!figures->error.empty() && !checkpointErrorShown_) {
    checkpointErrorShown_ = true;
    std::fprintf(stderr, "[slamdunk-live] checkpoint failed (tracking goes on): %s\n",
                 figures->error.c_str());
  }
}

}  // namespace slamdunk::live
