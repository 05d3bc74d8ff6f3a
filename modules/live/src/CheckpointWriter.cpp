#include <slamdunk/core/WorkerThread.h>
#include <slamdunk/live/CheckpointWriter.h>

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/grid_map/GridMapFiles.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk::live {

namespace {

/// Flushes a file or folder to the disk: the swap must not reach the disk before the data
/// does, or a power loss could leave a complete-looking folder of empty files.
void syncPath(const std::string& path, bool folder) {
  const int fd = ::open(path.c_str(), folder ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
  if (fd < 0) throw std::runtime_error("cannot open '" + path + "' to flush it");
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) throw std::runtime_error("cannot flush '" + path + "' to the disk");
}

void writeInfo(const std::string& path, const CheckpointInfo& info) {
  std::ofstream f(path);
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "# SlamDunk live checkpoint: resume with --load-map map.map (this folder)\n"
                "sequence = %zu\nframes_processed = %zu\nframes_tracked = %zu\nkeyframes = %zu\n"
                "last_frame_timestamp = %.6f\nunix_time = %.3f\n",
                info.sequence, info.framesProcessed, info.framesTracked, info.keyframes,
                info.lastFrameTimestamp, info.unixTime);
  f << buf;
  if (!info.gridMap.empty()) f << "grid_map = " << info.gridMap << "\n";
  f.flush();
  if (!f) throw std::runtime_error("cannot write '" + path + "'");
}

/// "out/cp/" and "out/./cp" name the folder "out/cp" (the temporary folder is named after it).
std::string normalFolder(const std::string& folder) {
  fs::path p = fs::path(folder).lexically_normal();
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
  return p.string();
}

/// A session killed while writing a checkpoint leaves its temporary folder beside the real one
/// (".<name>.tmp-<pid>-<n>", see AtomicOutputFolder): removed when its process is gone.
void removeAbandonedTemporaries(const fs::path& folder) {
  const std::string prefix = "." + folder.filename().string() + ".tmp-";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
      fs::remove_all(entry.path(), ec);
  }
}

}  // namespace

CheckpointInfo CheckpointInfo::read(const std::string& folder) {
  const std::string path = (fs::path(folder) / CheckpointWriter::kInfoFile).string();
  std::ifstream f(path);
  if (!f) throw std::runtime_error("checkpoint file '" + path + "' does not exist");
  std::map<std::string, std::string> values;
  for (std::string line; std::getline(f, line);) {
    if (line.empty() || line[0] == '#') continue;
    const size_t eq = line.find('=');
    if (eq == std::string::npos)
      throw std::runtime_error("'" + path + "': malformed line: " + line);
    auto trim = [](std::string s) {
      s.erase(0, s.find_first_not_of(" \t"));
      s.erase(s.find_last_not_of(" \t\r") + 1);
      return s;
    };
    values[trim(line.substr(0, eq))] = trim(line.substr(eq + 1));
  }
  auto number = [&](const char* key) {
    const auto it = values.find(key);
    if (it == values.end()) throw std::runtime_error("'" + path + "' has no '" + key + "'");
    try {
      size_t used = 0;
      const double v = std::stod(it->second, &used);
      if (used != it->second.size()) throw std::invalid_argument(it->second);
      return v;
    } catch (const std::exception&) {
      throw std::runtime_error("'" + path + "': '" + key + "' is not a number: " + it->second);
    }
  };
  CheckpointInfo info;
  info.sequence = static_cast<size_t>(number("sequence"));
  info.framesProcessed = static_cast<size_t>(number("frames_processed"));
  info.framesTracked = static_cast<size_t>(number("frames_tracked"));
  info.keyframes = static_cast<size_t>(number("keyframes"));
  info.lastFrameTimestamp = number("last_frame_timestamp");
  info.unixTime = number("unix_time");
  if (const auto it = values.find("grid_map"); it != values.end()) info.gridMap = it->second;
  return info;
}

CheckpointWriter::CheckpointWriter(const CheckpointOptions& options, std::string folder,
                                   std::shared_ptr<const KeyframeGraph> graph, FrameLog& frames,
                                   std::string description)
    : options_(options),
      folder_(normalFolder(folder)),
      description_(std::move(description)),
      graph_(std::move(graph)),
      frames_(frames) {
  if (folder_.empty()) throw std::invalid_argument("checkpoint folder not set");
  const fs::path parent = fs::absolute(folder_).parent_path();
  if (!fs::is_directory(parent))
    throw std::runtime_error("checkpoint folder '" + folder_ + "': its parent folder '" +
                             parent.string() + "' does not exist");
  figures_.folder = folder_;
  removeAbandonedTemporaries(fs::absolute(folder_));
}

CheckpointWriter::~CheckpointWriter() { stop(); }

void CheckpointWriter::start() {
  if (!options_.enabled() || thread_.joinable()) return;
  thread_ = std::thread([this] { writerLoop(); });
}

void CheckpointWriter::frameProcessed(bool tracked, bool newKeyframe) {
  ++processed_;
  if (tracked) ++tracked_;
  if (!newKeyframe) return;
  ++newKeyframes_;
  if (dueByKeyframes()) {
    // Rare (once per interval): the lock makes sure the writer is either waiting or about to
    // look at the counters again, so the wake-up is not lost.
    std::lock_guard lock(mutex_);
    wake_.notify_one();
  }
}

bool CheckpointWriter::dueByKeyframes() const {
  return options_.everyKeyframes > 0 && newKeyframes_ - keyframesAtLast_ >= options_.everyKeyframes;
}

void CheckpointWriter::stop() { stopWorker(thread_, mutex_, wake_, stopping_); }

void CheckpointWriter::writerLoop() {
  // Serializing and compressing the map is the costly part: on a machine with few cores it
  // must yield to tracking. Linux applies a nice value to the calling thread alone.
  setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 10);
  const auto period = std::chrono::duration_cast<SteadyClock::duration>(
      std::chrono::duration<double>(options_.everySeconds));
  auto last = SteadyClock::now();
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    const auto deadline =
        options_.everySeconds > 0 ? last + period : SteadyClock::time_point::max();
    // Woken by a keyframe that makes one due, by stop(), or at the latest every second.
    wake_.wait_until(lock, std::min(deadline, SteadyClock::now() + std::chrono::seconds(1)),
                     [&] { return stopping_ || dueByKeyframes(); });
    if (stopping_) break;
    const bool dueByTime = SteadyClock::now() >= deadline;
    if (!dueByKeyframes() && !dueByTime) continue;
    if (processed_ == processedAtLast_) {  // nothing new since the last one
      last = SteadyClock::now();
      continue;
    }
    // The interval runs from one snapshot to the next: a slow write does not stretch it.
    last = SteadyClock::now();
    lock.unlock();
    write();
    lock.lock();
  }
}

void CheckpointWriter::writeNow() { write(); }

void CheckpointWriter::setSensorPose(const mrpt::poses::CPose3D& sensorPose) {
  std::lock_guard lock(mutex_);
  sensorPose_ = sensorPose;
}

void CheckpointWriter::write() {
  std::lock_guard writing(writeMutex_);
  const auto start = SteadyClock::now();
  const size_t keyframesNow = newKeyframes_.load();
  processedAtLast_ = processed_.load();
  try {
    // Records first, graph second: every record's keyframe is then in the snapshot.
    frames_.takeNew(copied_);
    const auto snapStart = SteadyClock::now();
    const std::shared_ptr<KeyframeGraph> graph = graph_->snapshot();
    const double snapshotMs = msSince(snapStart);
    const double unixTime =
        std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();

    Trajectory keyframes;
    for (const auto& [id, pose] : graph->poses())
      keyframes.push_back({graph->keyframe(id)->timestamp, pose});
    CheckpointInfo info;
    {
      std::lock_guard lock(mutex_);
      info.sequence = figures_.written + 1;
    }
    info.framesProcessed = copied_.size();
    info.keyframes = graph->keyframeCount();
    info.lastFrameTimestamp = copied_.empty() ? 0 : copied_.back().timestamp;
    info.unixTime = unixTime;

    AtomicOutputFolder out(folder_);
    const fs::path dir(out.tempPath());
    const std::string what = description_ + " (checkpoint " + std::to_string(info.sequence) + ")";
    // Stored, not compressed: compression was 90 % of a checkpoint's CPU (7-Scenes, 67
    // keyframes: 150-210 ms at gzip level 1, 8-19 ms stored) for a file 1.5x smaller.
    CKeyframeGraphMap(graph).saveToFile((dir / kMapFile).string(), 0);
    // Streamed from the records: a vector of every pose, made and freed at each checkpoint,
    // grew with the session (144 B a frame, 8 MB after 30 minutes) and made the allocator keep
    // ever larger free blocks.
    TumTrajectoryWriter trajectory((dir / kTrajectoryFile).string(), what + ": tracked frames");
    info.framesTracked = forEachTrackedPose(
        copied_, *graph, [&](double t, const Pose& pose) { trajectory.add(t, pose); });
    trajectory.commit();
    writeTumTrajectory((dir / kKeyframesFile).string(), keyframes, what + ": keyframes");
    std::vector<std::string> files{kMapFile, kTrajectoryFile, kKeyframesFile, kInfoFile};
    if (gridMap_) {
      std::optional<mrpt::poses::CPose3D> sensorPose;
      {
        std::lock_guard lock(mutex_);
        sensorPose = sensorPose_;
      }
      try {
        writeGridMap(GridMapBuilder(*gridMap_).build(*graph, sensorPose),
                     (dir / kGridMapPrefix).string());
        for (const std::string& ext : gridMapExtensions()) files.push_back(kGridMapPrefix + ext);
        info.gridMap = kGridMapPrefix + gridMapExtensions().front();
      } catch (const std::runtime_error& e) {
        info.gridMap = std::string("none: ") + e.what();  // no floor seen yet, say
      }
    }
    writeInfo((dir / kInfoFile).string(), info);
    for (const std::string& file : files) syncPath((dir / file).string(), false);
    syncPath(dir.string(), true);
    out.commit();
    // The swap itself is an entry of the parent folder.
    syncPath(fs::absolute(folder_).parent_path().string(), true);

    keyframesAtLast_ = keyframesNow;
    std::lock_guard lock(mutex_);
    ++figures_.written;
    figures_.snapshotMs.push_back(snapshotMs);
    figures_.totalMs.push_back(msSince(start));
  } catch (const std::exception& e) {
    // A full disk must not end the session: tracking goes on, the next checkpoint tries again,
    // and the summary reports the failure.
    keyframesAtLast_ = keyframesNow;
    std::lock_guard lock(mutex_);
    if (figures_.error.empty()) figures_.error = e.what();
  }
}

CheckpointFigures CheckpointWriter::figures() const {
  std::lock_guard lock(mutex_);
  return figures_;
}

}  // namespace slamdunk::live
