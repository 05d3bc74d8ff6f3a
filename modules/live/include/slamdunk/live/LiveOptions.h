#pragma once
// The live INI: section [slamdunk-live] (the live pipeline's settings, read strictly), a
// frame-source section named by its `source` key (rawlog-grabber style: `driver =
// COpenNI2Sensor`, ... or `driver = replay`), and the pipeline parameters: a separate pipeline
// INI named by `pipeline_config` and/or sections [pipeline.features] [pipeline.tracker]
// [pipeline.optimizer] [pipeline.slam] in the live INI itself, applied on top. The prefix keeps
// the pipeline's strict section check away from the sensor's sections.
//
// A program that builds its own source (an app-owned sensor, pushed observations) can fill
// LiveOptions in code instead: every member has a usable default.

#include <slamdunk/slam/SlamOptions.h>

#include <mrpt/config/CConfigFile.h>

#include <memory>
#include <string>

namespace slamdunk::live {

/// Crash safety: the trajectory so far and the keyframe map are written to a folder every
/// `everyKeyframes` new keyframes or `everySeconds` seconds, whichever comes first, by a thread
/// of their own; a session killed outright (SIGKILL, power loss) loses at most one interval.
struct CheckpointOptions {
  size_t everyKeyframes = 10;  ///< 0 = not by keyframe count
  double everySeconds = 30;    ///< 0 = not by time
  /// Where the checkpoint folder goes; empty = beside the trajectory output, named
  /// "<trajectory name without extension>_checkpoint".
  std::string folder;

  bool enabled() const { return everyKeyframes > 0 || everySeconds > 0; }
};

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
  /// A camera driver's stamp, ms after the middle of the colour exposure (SensorFrameSource::
  /// setStampLatencyMs); camera drivers only: rawlogs replayed hold exposure-time stamps.
  double sensorStampLatencyMs = 0;
  CheckpointOptions checkpoint;
  SlamOptions slam = liveSlamDefaults();  ///< the live defaults below, then the INI's values
  std::shared_ptr<mrpt::config::CConfigFile> config;  ///< kept for the source section

  /// Its INI keys (section [slamdunk-live]); the pipeline's sections are SlamOptions'.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("source", o.sourceSection);
    k("pipeline_config", o.pipelineConfig);
    k("queue_capacity", o.queueCapacity);
    k("status_period", o.statusPeriod);
    k("open_timeout", o.openTimeout);
    k("frame_timeout", o.frameTimeout);
    k("sensor_stamp_latency_ms", o.sensorStampLatencyMs);
    k("checkpoint_every_keyframes", o.checkpoint.everyKeyframes);
    k("checkpoint_every_seconds", o.checkpoint.everySeconds);
    k("checkpoint_folder", o.checkpoint.folder);
  }

  /// Throws std::runtime_error naming the file and the bad key or section.
  static LiveOptions fromFile(const std::string& path);

  /// The pipeline's defaults changed for live use: the local optimization runs in its own
  /// thread, and a feature pool is handed over as soon as it is ready, so tracking never waits
  /// for either.
  static SlamOptions liveSlamDefaults(SlamOptions base = {});
};

}  // namespace slamdunk::live
