#include <slamdunk/live/FrameSource.h>

#include <slamdunk/live/ReplayFrameSource.h>
#include <slamdunk/live/SensorFrameSource.h>

#include <slamdunk/core/IniOptions.h>

#include <filesystem>
#include <stdexcept>

namespace slamdunk::live {

namespace {
std::string resolve(const std::string& path, const std::string& baseDir) {
  const std::filesystem::path p(path);
  if (path.empty() || !p.is_relative() || baseDir.empty()) return path;
  return (std::filesystem::path(baseDir) / p).string();
}
}  // namespace

std::unique_ptr<FrameSource> makeFrameSource(const mrpt::config::CConfigFileBase& cfg,
                                             const std::string& section, const std::string& iniDir,
                                             const SourceOverrides& overrides,
                                             double frameTimeoutSeconds,
                                             double sensorStampLatencyMs) {
  if (!cfg.sectionExists(section))
    throw std::runtime_error("source section [" + section + "] is not in the INI");
  const std::string driver = cfg.read_string(section, "driver", "");
  if (driver.empty())
    throw std::runtime_error("[" + section +
                             "] has no 'driver' key (replay, or an MRPT sensor "
                             "class such as COpenNI2Sensor)");
  if (driver == "replay") {
    // Our own section: read strictly, so a misspelled key is an error, not a silent default.
    IniSectionReader r(cfg, section);
    r.readString("driver", "");
    std::string rawlog = r.readString("rawlog", "");
    double speed = r.readDouble("speed", 1.0);
    const int loops = r.readInt("loops", 1);
    const int readAhead =
        r.readInt("read_ahead_frames", static_cast<int>(ReplayFrameSource::kDefaultReadAhead));
    r.rejectUnknownKeys();
    rawlog = overrides.rawlog ? *overrides.rawlog : resolve(rawlog, iniDir);
    if (overrides.speed) speed = *overrides.speed;
    if (rawlog.empty())
      throw std::runtime_error("no rawlog to replay: set [" + section +
                               "] rawlog or pass --rawlog");
    if (!(speed > 0)) throw std::runtime_error("replay speed must be > 0 (1 = real time)");
    if (loops < 0)
      throw std::runtime_error("[" + section + "] loops must be >= 0 (0 = until stopped)");
    if (readAhead < 1)
      throw std::runtime_error("[" + section +
                               "] read_ahead_frames must be >= 1 (frames decoded "
                               "ahead of their due time)");
    // tum2rawlog and --record write the exposure's instant already: a second correction would
    // put every frame early.
    if (sensorStampLatencyMs != 0)
      throw std::runtime_error(
          "sensor_stamp_latency_ms applies to camera drivers, not to [" + section +
          "] driver = replay: a rawlog's stamps are taken as they are (tum2rawlog and --record "
          "write the exposure's instant)");
    return std::make_unique<ReplayFrameSource>(rawlog, speed, loops,
                                               static_cast<size_t>(readAhead));
  }
  if (overrides.rawlog || overrides.speed)
    throw std::runtime_error("--rawlog and --speed apply to a replay source only; [" + section +
                             "] uses driver " + driver);
  auto sensor = std::make_unique<SensorFrameSource>(cfg, section, driver, frameTimeoutSeconds);
  sensor->setStampLatencyMs(sensorStampLatencyMs);
  return sensor;
}

}  // namespace slamdunk::live
