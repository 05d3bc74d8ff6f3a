#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/features/FramePreparation.h>

#include <mrpt/system/datetime.h>

namespace slamdunk {

double PreparedFrame::timestamp() const {
  return observation ? mrpt::Clock::toDouble(observation->timestamp) : 0.0;
}

PreparedFrame PreparedFrame::of(mrpt::obs::CObservation3DRangeScan::Ptr observation,
                                const FeatureExtractor& extractor) {
  PreparedFrame p;
  p.observation = std::move(observation);
  try {
    p.frame = RgbdFrame::fromObservation(*p.observation);
    const auto start = SteadyClock::now();
    p.features = extractor.extract(*p.frame);
    p.extractionMs = msSince(start);
  } catch (const std::exception& e) {
    p.frame.reset();
    p.error = e.what();
  }
  return p;
}

FramePrefetcher::FramePrefetcher(Source source, const FeatureOptions& features, size_t depth)
    : source_(std::move(source)),
      extractor_(features),
      prefetcher_(
          [this]() -> std::optional<PreparedFrame> {
            auto observation = source_();
            if (!observation) return std::nullopt;
            return PreparedFrame::of(std::move(observation), extractor_);
          },
          depth) {}

}  // namespace slamdunk
