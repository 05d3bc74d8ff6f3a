#include <slamdunk/live/SensorFrameSource.h>

#include "StdoutToStderr.h"

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/TumSequence.h>

#include <mrpt/hwdrivers/COpenNI2Generic.h>
#include <mrpt/io/lazy_load_path.h>
#include <mrpt/serialization/CArchive.h>

#include <stdexcept>
#include <thread>
#include <vector>

namespace slamdunk::live {

namespace {
using Clock = std::chrono::steady_clock;

/// MRPT exceptions carry a call stack after the message: keep the first meaningful line.
std::string firstLine(const std::string& what) {
  std::string s = what;
  const std::string tag = "Message:";
  if (const size_t m = s.find(tag); m != std::string::npos) s = s.substr(m + tag.size());
  const size_t a = s.find_first_not_of(" \n");
  if (a == std::string::npos) return what;
  s = s.substr(a);
  return s.substr(0, s.find('\n'));
}
}  // namespace

SensorFrameSource::SensorFrameSource(const mrpt::config::CConfigFileBase& cfg, std::string section,
                                     std::string driver, double frameTimeoutSeconds)
    : section_(std::move(section)), driver_(std::move(driver)), frameTimeout_(frameTimeoutSeconds) {
  StdoutToStderr quiet;
  sensor_ = mrpt::hwdrivers::CGenericSensor::createSensorPtr(driver_);
  if (!sensor_)
    throw std::runtime_error("[" + section_ + "] driver = " + driver_ +
                             ": not an MRPT sensor class (e.g. COpenNI2Sensor, CCameraSensor) "
                             "nor 'replay'");
  if (driver_ == "COpenNI2Sensor") {
    const int serial = cfg.read_int(section_, "serial_number", 0);
    lookedFor_ =
        serial ? "serial_number = " + std::to_string(serial)
               : "device_number = " + std::to_string(cfg.read_int(section_, "device_number", 0));
  }
  // CCameraSensor's rawlog mode does not point MRPT's lazy-load path at the images folder
  // (detectImagesDirectory is wrong in 2.5.8), so externally stored images would not load.
  if (driver_ == "CCameraSensor" && cfg.read_string(section_, "grabber_type", "") == "rawlog")
    mrpt::io::setLazyLoadPathBase(
        RawlogReader::imagesDirectoryFor(cfg.read_string(section_, "rawlog_file", "")));
  try {
    sensor_->loadConfig(cfg, section_);
  } catch (const std::exception& e) {
    throw std::runtime_error("[" + section_ + "] (" + driver_ + "): " + firstLine(e.what()));
  }
}

SensorFrameSource::SensorFrameSource(mrpt::hwdrivers::CGenericSensor::Ptr sensor, bool initialized,
                                     double frameTimeoutSeconds)
    : frameTimeout_(frameTimeoutSeconds), initialized_(initialized), sensor_(std::move(sensor)) {
  if (!sensor_) throw std::invalid_argument("SensorFrameSource: no sensor given");
  if (!(frameTimeout_ > 0)) throw std::invalid_argument("SensorFrameSource: frame timeout <= 0");
  ownedByApplication_ = true;
  driver_ = sensor_->GetRuntimeClass()->className;
  section_ = sensor_->getSensorLabel();
}

void SensorFrameSource::setStampLatencyMs(double ms) {
  if (const std::string bad = stampLatencyProblem(ms); !bad.empty())
    throw std::invalid_argument("stamp latency " + bad);
  stampLatencyMs_ = ms;
}

SensorFrameSource::~SensorFrameSource() {
  // MRPT 2.5.8's ~COpenNI2Sensor() throws "No OpenNI2 devices found" when no device was opened,
  // which terminates the process: such a driver is never destroyed. It stays reachable from a
  // static list, so LeakSanitizer does not take the deliberate non-destruction for a leak.
  static auto* neverDestroyed = new std::vector<mrpt::hwdrivers::CGenericSensor::Ptr>;
  if (auto* ni = dynamic_cast<mrpt::hwdrivers::COpenNI2Generic*>(sensor_.get());
      ni && ni->getNumDevices() == 0)
    neverDestroyed->push_back(std::move(sensor_));
}

void SensorFrameSource::open() {
  if (!initialized_) {
    StdoutToStderr quiet;
    try {
      sensor_->initialize();
    } catch (const std::exception& e) {
      throw std::runtime_error(driver_ + " [" + section_ +
                               "] failed to start: " + firstLine(e.what()));
    }
  }
  checkOpenNI2Devices();
  if (sensor_->getState() == mrpt::hwdrivers::CGenericSensor::ssError)
    throw std::runtime_error(driver_ + " [" + section_ + "] reports an error after initialize()");
  nextPoll_ = Clock::now();
}

void SensorFrameSource::checkOpenNI2Devices() {
  // COpenNI2Sensor::initialize() succeeds with no camera and the first doProcess() then
  // aborts the process on an assertion: check here and explain instead.
  auto* ni = dynamic_cast<mrpt::hwdrivers::COpenNI2Generic*>(sensor_.get());
  if (!ni || ni->getNumDevices() > 0) return;
  int connected = 0;
  try {
    connected = ni->getConnectedDevices();
  } catch (const std::exception&) {
  }
  throw std::runtime_error(
      "OpenNI2 opened no RGB-D device: looked for " + lookedFor_ + " (section [" + section_ +
      "]), OpenNI2 found " + std::to_string(connected) +
      " connected device(s). Check that the camera (Asus Xtion / Kinect / PrimeSense) is "
      "plugged in and powered, that `lsusb` lists it (e.g. ID 1d27:0601 or 045e:02ae), that "
      "your user may access it (udev rules), and try MRPT's `rawlog-grabber` with the same "
      "INI; with several cameras, set device_number or serial_number.");
}

mrpt::obs::CObservation3DRangeScan::Ptr SensorFrameSource::next(const std::atomic<bool>& stop) {
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / std::max(1.0, sensor_->getProcessRate())));
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(frameTimeout_));
  while (pending_.empty()) {
    if (stop) return nullptr;
    if (Clock::now() > deadline)
      throw std::runtime_error(driver_ + " [" + section_ + "] delivered no RGB-D frame for " +
                               std::to_string(frameTimeout_) + " s (" +
                               std::to_string(otherObservations_) +
                               " other observations): is the camera still connected?");
    // Poll at process_rate, as rawlog-grabber does.
    std::this_thread::sleep_until(nextPoll_);
    nextPoll_ = std::max(nextPoll_ + period, Clock::now());
    try {
      sensor_->doProcess();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      return nullptr;  // CCameraSensor replaying a rawlog reached its end
    } catch (const std::exception& e) {
      throw std::runtime_error(driver_ + " [" + section_ + "]: " + firstLine(e.what()));
    }
    if (sensor_->getState() == mrpt::hwdrivers::CGenericSensor::ssError)
      throw std::runtime_error(driver_ + " [" + section_ + "] reports a hardware error");
    for (const auto& [time, o] : sensor_->getObservations()) {
      if (auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o))
        pending_.push_back(scan);
      else
        ++otherObservations_;
    }
  }
  auto obs = pending_.front();
  pending_.pop_front();
  loadExternalImages(*obs);  // CCameraSensor replaying a rawlog
  obs->timestamp -= std::chrono::duration_cast<mrpt::Clock::duration>(
      std::chrono::duration<double, std::milli>(stampLatencyMs_));
  return obs;
}

std::string SensorFrameSource::describe() const {
  char rate[32];
  std::snprintf(rate, sizeof(rate), "%g", sensor_->getProcessRate());
  return driver_ +
         (ownedByApplication_ ? " '" + section_ + "' (the application's sensor)"
                              : " from section [" + section_ + "]") +
         ", polled at " + rate + " Hz";
}

}  // namespace slamdunk::live
