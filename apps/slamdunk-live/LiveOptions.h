#pragma once
// The live INI: section [slamdunk-live] (this app's settings, read strictly), a frame-source
// section named by its `source` key (rawlog-grabber style: `driver = COpenNI2Sensor`, ... or
// `driver = replay`), and the pipeline parameters: a separate pipeline INI named by
// `pipeline_config` and/or sections [pipeline.features] [pipeline.tracker]
// [pipeline.optimizer] [pipeline.slam] in the live INI itself, applied on top. The prefix keeps
// the pipeline's strict section check away from the sensor's sections.

#include <slamdunk/slam/SlamOptions.h>

#include <mrpt/config/CConfigFile.h>

#include <memory>
#include <string>

namespace slamdunk::live {

struct LiveOptions {
  static constexpr const char* kSection = "slamdunk-live";
  static constexpr const char* kPipelinePrefix = "pipeline.";

  std::string iniPath;
  std::string iniDir;          ///< relative paths in the INI are relative to this folder
  std::string sourceSection;   ///< section describing the frame source
  std::string pipelineConfig;  ///< resolved path, empty = built-in defaults
  size_t queueCapacity = 4;    ///< frames waiting for the tracker; the oldest is dropped
  double statusPeriod = 1.0;   ///< s between status lines (0 = none)
  double openTimeout = 15.0;   ///< s allowed for the source to open
  double frameTimeout = 10.0;  ///< s without a frame from a camera before giving up
  SlamOptions slam;            ///< optimizer_thread defaults to true here (live use)
  std::shared_ptr<mrpt::config::CConfigFile> config;  ///< kept for the source section

  /// Throws std::runtime_error naming the file and the bad key or section.
  static LiveOptions fromFile(const std::string& path);
};

}  // namespace slamdunk::live
