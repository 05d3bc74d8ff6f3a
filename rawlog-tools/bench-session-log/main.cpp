// bench-session-log: what a session log's spill costs the thread that appends to it. A live
// session appends one FrameRecord per frame on its tracking thread; every SessionLog::kChunk
// records go to the log's temporary file in one write. Appends records at a frame rate and
// prints how long the appends that spilled took (median, p95, max) against the others, on a
// quiet disk or (--pressure) beside a thread that writes and flushes 100 MB every half second
// to the same temporary folder, as scripts/live-disk-stall.sh does to a live replay.

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/eval/TrajectoryMetrics.h>
#include <slamdunk/slam/SlamSystem.h>

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

using namespace slamdunk;

namespace {

using Clock = std::chrono::steady_clock;

/// Writes and flushes 100 MB every half second into a file of the temporary folder until stopped.
class DiskPressure {
 public:
  DiskPressure() {
    const char* dir = std::getenv("TMPDIR");
    path_ = std::string(dir && *dir ? dir : "/tmp") + "/bench-session-log-pressure.tmp";
    thread_ = std::thread([this] { run(); });
  }
  /// The pressure file could not be created (then there was no pressure).
  bool failed() const { return failed_; }
  const std::string& path() const { return path_; }
  ~DiskPressure() {
    stop_ = true;
    thread_.join();
    ::unlink(path_.c_str());
  }

 private:
  void run() {
    const std::vector<char> block(1 << 20, 0);
    while (!stop_) {
      const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
      if (fd < 0) {
        failed_ = true;
        return;
      }
      for (int i = 0; i < 100 && !stop_; ++i)
        if (::write(fd, block.data(), block.size()) < 0) break;
      ::fsync(fd);
      ::close(fd);
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }
  std::string path_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> failed_{false};
  std::thread thread_;
};

}  // namespace

int main(int argc, char** argv) {
  return slamdunk::runTool("bench-session-log", [&] {
    TCLAP::CmdLine cmd(
        "Session log benchmark: how long the appends that spill a chunk to the log's temporary "
        "file take, on a quiet disk or beside a process flushing 100 MB every 0.5 s.",
        ' ', "1.0");
    TCLAP::ValueArg<int> argChunks("c", "chunks", "spills to measure (default 30)", false, 30, "N",
                                   cmd);
    TCLAP::ValueArg<double> argHz("", "hz",
                                  "records appended per second (default 1000; a camera gives 30)",
                                  false, 1000, "F", cmd);
    TCLAP::SwitchArg argPressure("", "pressure",
                                 "write and flush 100 MB every 0.5 s beside it, in TMPDIR", cmd);
    if (const auto exitCode = parseCommandLine(cmd, argc, argv, "bench-session-log"))
      return *exitCode;
    if (argChunks.getValue() < 1 || !(argHz.getValue() > 0))
      throw std::invalid_argument("--chunks and --hz must be > 0");
    std::unique_ptr<DiskPressure> pressure;
    if (argPressure.getValue()) pressure = std::make_unique<DiskPressure>();
    SessionLog<FrameRecord> log;
    std::vector<double> spilling, others;
    const auto period = std::chrono::duration<double>(1.0 / argHz.getValue());
    auto next = Clock::now();
    const size_t records =
        static_cast<size_t>(argChunks.getValue()) * SessionLog<FrameRecord>::kChunk;
    for (size_t i = 0; i < records; ++i) {
      FrameRecord record;
      record.timestamp = i / 30.0;
      record.status = TrackingStatus::Tracked;
      const size_t inMemory = log.entriesInMemory();
      const auto start = Clock::now();
      log.push_back(record);
      const double ms = msSince(start);
      (log.entriesInMemory() < inMemory ? spilling : others).push_back(ms);
      next += std::chrono::duration_cast<Clock::duration>(period);
      std::this_thread::sleep_until(next);
    }
    if (pressure && pressure->failed())
      throw std::runtime_error("cannot write the pressure file " + pressure->path());
    if (spilling.empty())
      throw std::runtime_error("no spill happened: the temporary folder cannot be written");
    std::printf("%s: %zu records, %zu spills (%zu KiB each)\n",
                argPressure.getValue() ? "disk under pressure" : "quiet disk", records,
                spilling.size(),
                SessionLog<FrameRecord>::kChunk * SessionLogCodec<FrameRecord>::kBytes / 1024);
    const auto spills = eval::ErrorStatistics::compute(spilling);
    const auto rest = eval::ErrorStatistics::compute(others);
    std::printf("append that spills  ms median %.3f  p95 %.3f  max %.3f\n", spills.median,
                spills.p95, spills.max);
    std::printf("other appends       ms median %.4f  p95 %.4f  max %.3f\n", rest.median, rest.p95,
                rest.max);
    return 0;
  });
}
