#pragma once
// Any MRPT CGenericSensor that delivers CObservation3DRangeScan (COpenNI2Sensor, CKinect,
// CCameraSensor with grabber_type = rawlog, ...), polled at its process_rate as rawlog-grabber
// does: either created from an INI section exactly as rawlog-grabber creates it, or a sensor
// the application created and configured itself. Other observation types are skipped
// (counted). While the pipeline runs, only its grabber thread may call the sensor.

#include <slamdunk/live/FrameSource.h>

#include <mrpt/hwdrivers/CGenericSensor.h>

#include <chrono>
#include <deque>

namespace slamdunk::live {

class SensorFrameSource : public FrameSource {
 public:
  /// Creates the driver and loads its section (no device access yet); throws on an unknown
  /// driver or a section MRPT rejects.
  SensorFrameSource(const mrpt::config::CConfigFileBase& cfg, std::string section,
                    std::string driver, double frameTimeoutSeconds);
  /// A sensor the application owns, already configured (loadConfig or setters). open() calls
  /// its initialize() unless `initialized` says the application already did.
  explicit SensorFrameSource(mrpt::hwdrivers::CGenericSensor::Ptr sensor, bool initialized = false,
                             double frameTimeoutSeconds = 10.0);
  ~SensorFrameSource() override;

  /// The driver stamps a frame this long after the middle of its colour exposure (a Kinect v1
  /// through OpenNI: about half its 25 ms readout, as tum-fr1.ini says); every frame's stamp is
  /// moved back by it, to the instant the pipeline takes a stamp for. Throws beyond +-100 ms.
  void setStampLatencyMs(double ms);

  void open() override;
  mrpt::obs::CObservation3DRangeScan::Ptr next(const std::atomic<bool>& stop) override;
  std::string describe() const override;

 private:
  void checkOpenNI2Devices();

  std::string section_, driver_;
  std::string lookedFor_;  ///< e.g. "device_number = 0": named in the no-device message
  double frameTimeout_;
  double stampLatencyMs_ = 0;
  bool initialized_ = false;
  bool ownedByApplication_ = false;

  mrpt::hwdrivers::CGenericSensor::Ptr sensor_;
  std::deque<mrpt::obs::CObservation3DRangeScan::Ptr>
      pending_;  ///< one doProcess() can yield several
  std::chrono::steady_clock::time_point nextPoll_;
  size_t otherObservations_ = 0;
};

}  // namespace slamdunk::live
