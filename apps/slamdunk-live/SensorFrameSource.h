#pragma once
// Any MRPT CGenericSensor that delivers CObservation3DRangeScan (COpenNI2Sensor, CKinect,
// CCameraSensor with grabber_type = rawlog, ...), configured from its INI section exactly as
// rawlog-grabber does and polled at the section's process_rate.

#include "FrameSource.h"

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
  ~SensorFrameSource() override;

  void open() override;
  mrpt::obs::CObservation3DRangeScan::Ptr next(const std::atomic<bool>& stop) override;
  std::string describe() const override;

 private:
  void checkOpenNI2Devices();

  std::string section_, driver_;
  std::string lookedFor_;  ///< e.g. "device_number = 0": named in the no-device message
  double frameTimeout_;
  mrpt::hwdrivers::CGenericSensor::Ptr sensor_;
  std::deque<mrpt::obs::CObservation3DRangeScan::Ptr>
      pending_;  ///< one doProcess() can yield several
  std::chrono::steady_clock::time_point nextPoll_;
  size_t otherObservations_ = 0;
};

}  // namespace slamdunk::live
