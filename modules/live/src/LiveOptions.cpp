#include <slamdunk/live/LiveOptions.h>

#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/IniOptions.h>
#include <slamdunk/core/TumSequence.h>

#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk::live {

SlamOptions LiveOptions::liveSlamDefaults(SlamOptions base) {
  base.optimizerThread = true;
  base.tracker.localMap.handoverFrames = 0;
  return base;
}

LiveOptions LiveOptions::fromFile(const std::string& path) {
  if (!fs::is_regular_file(path))
    throw std::runtime_error("configuration file '" + path + "' does not exist");
  LiveOptions o;
  o.iniPath = path;
  o.iniDir = fs::path(path).parent_path().string();
  try {
    // Inside the try: MRPT's parser itself throws on some malformed files (e.g. "${X}" naming
    // an undefined variable), and that error must name the file too.
    o.config = std::make_shared<mrpt::config::CConfigFile>(path);
    IniSectionReader r(*o.config, kSection);
    if (!r.sectionExists()) throw std::runtime_error(std::string("no [") + kSection + "] section");
    o.sourceSection = r.readString("source", "");
    const std::string pipeline = r.readString("pipeline_config", "");
    const int capacity = r.readInt("queue_capacity", static_cast<int>(o.queueCapacity));
    o.statusPeriod = r.readDouble("status_period", o.statusPeriod);
    o.openTimeout = r.readDouble("open_timeout", o.openTimeout);
    o.frameTimeout = r.readDouble("frame_timeout", o.frameTimeout);
    o.sensorStampLatencyMs = r.readDouble("sensor_stamp_latency_ms", o.sensorStampLatencyMs);
    const int everyKeyframes =
        r.readInt("checkpoint_every_keyframes", static_cast<int>(o.checkpoint.everyKeyframes));
    o.checkpoint.everySeconds = r.readDouble("checkpoint_every_seconds", o.checkpoint.everySeconds);
    o.checkpoint.folder = r.readString("checkpoint_folder", "");
    r.rejectUnknownKeys();
    if (o.sourceSection.empty())
      throw std::runtime_error(std::string("[") + kSection +
                               "] source: name the section that describes the frame source");
    if (capacity < 1)
      throw std::runtime_error(std::string("[") + kSection + "] queue_capacity must be >= 1");
    if (o.openTimeout <= 0 || o.frameTimeout <= 0)
      throw std::runtime_error(std::string("[") + kSection + "] timeouts must be > 0");
    o.queueCapacity = static_cast<size_t>(capacity);
    if (const std::string bad = stampLatencyProblem(o.sensorStampLatencyMs); !bad.empty())
      throw std::runtime_error(std::string("[") + kSection + "] sensor_stamp_latency_ms " + bad);
    if (everyKeyframes < 0 || !(o.checkpoint.everySeconds >= 0))
      throw std::runtime_error(std::string("[") + kSection +
                               "] checkpoint_every_keyframes and checkpoint_every_seconds must "
                               "be >= 0 (0 = off)");
    o.checkpoint.everyKeyframes = static_cast<size_t>(everyKeyframes);
    if (!o.checkpoint.folder.empty() && fs::path(o.checkpoint.folder).is_relative())
      o.checkpoint.folder = (fs::path(o.iniDir) / o.checkpoint.folder).string();

    if (!pipeline.empty()) {
      const fs::path p(pipeline);
      o.pipelineConfig = p.is_relative() ? (fs::path(o.iniDir) / p).string() : pipeline;
      o.slam = SlamOptions::fromFile(o.pipelineConfig);
    }
    // Live: tracking must never wait for the local optimization nor for a feature pool. Set
    // after the pipeline file (whose defaults are for offline runs) and before the overrides,
    // so an explicit [pipeline.slam] optimizer_thread = false still wins.
    o.slam = liveSlamDefaults(o.slam);
    o.slam.loadFromConfigFile(*o.config, kPipelinePrefix);
  } catch (const std::exception& e) {
    throw std::runtime_error("configuration file '" + path + "': " + summarizeError(e.what()));
  }
  return o;
}

}  // namespace slamdunk::live
