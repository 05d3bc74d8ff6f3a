#include "LiveOptions.h"

#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/IniOptions.h>

#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk::live {

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
    r.rejectUnknownKeys();
    if (o.sourceSection.empty())
      throw std::runtime_error(std::string("[") + kSection +
                               "] source: name the section that describes the frame source");
    if (capacity < 1)
      throw std::runtime_error(std::string("[") + kSection + "] queue_capacity must be >= 1");
    if (o.openTimeout <= 0 || o.frameTimeout <= 0)
      throw std::runtime_error(std::string("[") + kSection + "] timeouts must be > 0");
    o.queueCapacity = static_cast<size_t>(capacity);

    if (!pipeline.empty()) {
      const fs::path p(pipeline);
      o.pipelineConfig = p.is_relative() ? (fs::path(o.iniDir) / p).string() : pipeline;
      o.slam = SlamOptions::fromFile(o.pipelineConfig);
    }
    // Live: tracking must never wait for the local optimization. Set after the pipeline file
    // (whose default says false, for offline runs) and before the overrides, so an explicit
    // [pipeline.slam] optimizer_thread = false still wins.
    o.slam.optimizerThread = true;
    // Nor for a feature pool: each is handed over as soon as it is ready.
    o.slam.tracker.poolHandoverFrames = 0;
    o.slam.loadFromConfigFile(*o.config, kPipelinePrefix);
  } catch (const std::exception& e) {
    throw std::runtime_error("configuration file '" + path + "': " + summarizeError(e.what()));
  }
  return o;
}

}  // namespace slamdunk::live
