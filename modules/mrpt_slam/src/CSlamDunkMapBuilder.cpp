#include <slamdunk/mrpt_slam/CSlamDunkMapBuilder.h>
#include <slamdunk/slam/SimpleMapExport.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/poses/CPosePDF.h>

#include <stdexcept>

namespace slamdunk {

CSlamDunkMapBuilder::CSlamDunkMapBuilder(const SlamOptions& options) : options_(options) {
  setLoggerName("CSlamDunkMapBuilder");
  reset();
}

CSlamDunkMapBuilder::~CSlamDunkMapBuilder() = default;

void CSlamDunkMapBuilder::reset() {
  // The old system (and its optimizer thread) goes before the new one starts.
  system_.reset();
  system_ = std::make_unique<SlamSystem>(options_);
  keyframeMap_ = std::make_shared<CKeyframeGraphMap>(system_->graph());
  metricMap_.maps.clear();
  metricMap_.maps.push_back(keyframeMap_);
  last_ = TrackingResult();
  anyTracked_ = false;
}

void CSlamDunkMapBuilder::initialize(const mrpt::maps::CSimpleMap& initialMap,
                                     const mrpt::poses::CPosePDF* x0) {
  if (!initialMap.empty())
    throw std::invalid_argument(
        "CSlamDunkMapBuilder::initialize: starting from a non-empty CSimpleMap is not supported");
  std::lock_guard lock(mutex_);
  reset();
  worldOffset_ = x0 ? mrpt::poses::CPose3D(x0->getMeanVal()) : mrpt::poses::CPose3D();
}

void CSlamDunkMapBuilder::processActionObservation(mrpt::obs::CActionCollection&,
                                                   mrpt::obs::CSensoryFrame& observations) {
  if (!options.enableMapUpdating) return;
  for (const auto& obs : observations) {
    const auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs);
    if (!scan) continue;
    const TrackingResult r = system_->process(*scan);
    std::lock_guard lock(mutex_);
    // While lost, the result's pose is the last good one: keep reporting it.
    if (r.status != TrackingStatus::Lost || !anyTracked_)
      last_ = r;
    else
      last_.status = r.status;
    anyTracked_ = anyTracked_ || r.status != TrackingStatus::Lost;
    MRPT_LOG_DEBUG_STREAM("frame " << system_->frames().size() << ": "
                                   << (r.status == TrackingStatus::Lost ? "lost" : "tracked")
                                   << (r.newKeyframe ? ", new keyframe" : ""));
  }
}

mrpt::poses::CPose3DPDF::Ptr CSlamDunkMapBuilder::getCurrentPoseEstimation() const {
  std::lock_guard lock(mutex_);
  auto pdf = mrpt::poses::CPose3DPDFGaussian::Create();
  pdf->mean = worldOffset_ + toCPose3D(toMrptSensorWorld(last_.pose));
  return pdf;
}

void CSlamDunkMapBuilder::getCurrentlyBuiltMap(mrpt::maps::CSimpleMap& out_map) const {
  out_map = buildSimpleMap(*system_->graph(), true);
  std::lock_guard lock(mutex_);
  for (size_t k = 0; k < out_map.size(); ++k) {
    auto& pair = out_map.getAsPair(k);
    auto moved = mrpt::poses::CPose3DPDFGaussian::Create();
    moved->mean = worldOffset_ + pair.pose->getMeanVal();
    pair.pose = moved;
  }
}

unsigned int CSlamDunkMapBuilder::getCurrentlyBuiltMapSize() {
  return static_cast<unsigned int>(system_->graph()->keyframeCount());
}

const mrpt::maps::CMultiMetricMap* CSlamDunkMapBuilder::getCurrentlyBuiltMetricMap() const {
  return &metricMap_;
}

void CSlamDunkMapBuilder::saveCurrentEstimationToImage(const std::string& file, bool) {
  MRPT_LOG_WARN_STREAM("saveCurrentEstimationToImage('"
                       << file << "'): not supported by SlamDunk's 3D map; nothing written. "
                       << "Use CKeyframeGraphMap::saveMetricMapRepresentationToFile instead.");
}

void CSlamDunkMapBuilder::finish() { system_->finish(); }

TrackingResult CSlamDunkMapBuilder::lastResult() const {
  std::lock_guard lock(mutex_);
  return last_;
}

size_t CSlamDunkMapBuilder::framesProcessed() const { return system_->frames().size(); }

}  // namespace slamdunk
