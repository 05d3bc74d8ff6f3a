#pragma once
// Where live frames come from: a camera (any MRPT CGenericSensor, e.g. COpenNI2Sensor) or a
// rawlog replayed in real time. The grabber thread owns the source and calls it in a loop.

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <atomic>
#include <memory>
#include <optional>
#include <string>

namespace slamdunk::live {

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  /// Connects to the device or opens the file. Throws std::runtime_error with a message that
  /// tells the user what was looked for and what to check.
  virtual void open() = 0;

  /// Blocks until the next frame is available (a camera) or due (a replay), with its images
  /// decoded in memory. nullptr at the end of the stream or once `stop` is set. Throws on a
  /// device error or when no frame arrives within the source's timeout.
  virtual mrpt::obs::CObservation3DRangeScan::Ptr next(const std::atomic<bool>& stop) = 0;

  /// One line for the log: driver and what it reads.
  virtual std::string describe() const = 0;
};

/// Command-line settings that override the source section of the live INI (replay only).
struct SourceOverrides {
  std::optional<std::string> rawlog;
  std::optional<double> speed;
};

/// Builds the source described by INI section `section`: `driver = replay` is this app's
/// real-time rawlog player; any other driver is an MRPT CGenericSensor class name.
/// Relative paths are resolved against `iniDir`. A camera driver's frames are stamped
/// `sensorStampLatencyMs` earlier (SensorFrameSource::setStampLatencyMs); a replay source with a
/// latency is an error (its rawlog's stamps are taken as they are). Throws std::runtime_error on
/// a bad section.
std::unique_ptr<FrameSource> makeFrameSource(const mrpt::config::CConfigFileBase& cfg,
                                             const std::string& section, const std::string& iniDir,
                                             const SourceOverrides& overrides,
                                             double frameTimeoutSeconds,
                                             double sensorStampLatencyMs = 0);

}  // namespace slamdunk::live
