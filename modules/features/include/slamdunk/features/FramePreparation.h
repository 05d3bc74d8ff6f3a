#pragma once
// What tracking needs of an observation before it can match anything: the frame built from it
// and the frame's features. Both depend on the observation alone, so they can be made ahead,
// on another thread, while the tracker registers the frame before (FramePrefetcher): offline,
// the tracking thread then spends its time on matching, registration and mapping.

#include <slamdunk/core/Prefetcher.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/features/FeatureExtractor.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <functional>
#include <optional>
#include <string>

namespace slamdunk {

struct PreparedFrame {
  mrpt::obs::CObservation3DRangeScan::Ptr observation;
  /// Unset when the observation is unusable (no depth, sizes that disagree, ...): `error` says
  /// why, naming it.
  std::optional<RgbdFrame> frame;
  std::string error;
  FeatureSet features;
  double extractionMs = 0;  ///< extracting the features

  double timestamp() const;
  /// Builds the frame and extracts its features, on the calling thread. Never throws for a
  /// malformed observation: `error` tells.
  static PreparedFrame of(mrpt::obs::CObservation3DRangeScan::Ptr observation,
                          const FeatureExtractor& extractor);
};

/// Prepares the observations of a source a few frames ahead, on a thread of its own, in the
/// source's order.
class FramePrefetcher {
 public:
  /// Frames prepared ahead by default: enough for the preparing thread to go on through an
  /// inline local optimization (24 ms median on 7-Scenes, about three frames' extraction), at
  /// about 3 MiB a frame (its images and the frame made of them). With two it waited there.
  static constexpr size_t kDefaultDepth = 4;

  /// The next observation; nullptr at the end. An exception it throws (a damaged recording)
  /// is rethrown by next() at its place.
  using Source = std::function<mrpt::obs::CObservation3DRangeScan::Ptr()>;

  FramePrefetcher(Source source, const FeatureOptions& features, size_t depth = kDefaultDepth);

  /// The next prepared frame; std::nullopt at the end.
  std::optional<PreparedFrame> next() { return prefetcher_.next(); }

 private:
  Source source_;
  FeatureExtractor extractor_;
  Prefetcher<PreparedFrame> prefetcher_;  ///< last: stopped before what it uses
};

}  // namespace slamdunk
