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
    if (!o.config->sectionExists(kSection))
      throw std::runtime_error(std::string("no [") + kSection + "] section");
    loadIniKeys(o, *o.config, kSection);
    const SectionChecks require(kSection);
    require(!o.sourceSection.empty(), "source: name the section that describes the frame source");
    require(o.queueCapacity >= 1, "queue_capacity must be >= 1");
    require(o.openTimeout > 0 && o.frameTimeout > 0, "timeouts must be > 0");
    const std::string badLatency = stampLatencyProblem(o.sensorStampLatencyMs);
    require(badLatency.empty(), "sensor_stamp_latency_ms " + badLatency);
    require(o.checkpoint.everySeconds >= 0, "checkpoint_every_seconds must be >= 0 (0 = off)");
    auto besideTheIni = [&](std::string& path) {
      if (!path.empty() && fs::path(path).is_relative())
        path = (fs::path(o.iniDir) / path).string();
    };
    besideTheIni(o.checkpoint.folder);
    besideTheIni(o.pipelineConfig);
    if (!o.pipelineConfig.empty()) o.slam = SlamOptions::fromFile(o.pipelineConfig);
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
