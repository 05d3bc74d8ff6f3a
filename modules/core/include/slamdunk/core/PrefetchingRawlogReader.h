#pragma once
// Reads and decodes the next range scans of a rawlog on a thread of its own, so that loading
// (external PNGs, depth matrices) overlaps the processing of the frame before: offline, the
// whole-app rate is the tracking rate, not tracking plus decoding.

#include <slamdunk/core/Prefetcher.h>
#include <slamdunk/core/RawlogReader.h>

#include <mutex>

namespace slamdunk {

class PrefetchingRawlogReader {
 public:
  static constexpr size_t kDefaultDepth = 4;

  /// Opens the rawlog (throws like RawlogReader) and starts reading up to `depth` scans ahead.
  /// The first `firstScan` range scans are read past without loading their images.
  explicit PrefetchingRawlogReader(const std::string& path, size_t depth = kDefaultDepth,
                                   size_t firstScan = 0);
  PrefetchingRawlogReader(const PrefetchingRawlogReader&) = delete;
  PrefetchingRawlogReader& operator=(const PrefetchingRawlogReader&) = delete;

  /// The next range scan with its images loaded, in file order; nullptr at the end. Rethrows,
  /// at the scan where it happened, an error reading the file or loading the images.
  mrpt::obs::CObservation3DRangeScan::Ptr next();

  /// Counts as of the scans handed out so far (the reader may be ahead).
  size_t entriesRead() const;
  size_t otherObservationsSkipped() const;
  const std::string& path() const { return reader_.path(); }

 private:
  struct Item {
    mrpt::obs::CObservation3DRangeScan::Ptr scan;
    size_t entriesRead = 0, skipped = 0;  ///< the reader's counts once it had read `scan`
  };
  std::optional<Item> read();
  void handedOut(size_t entriesRead, size_t skipped);

  RawlogReader reader_;
  size_t scansToPass_;  ///< of the first scans, those not yet read past (reading thread only)
  mutable std::mutex countsMutex_;
  size_t entriesRead_ = 0, skipped_ = 0;  ///< of the last item handed out
  Prefetcher<Item> prefetcher_;           ///< last: stopped before the reader it reads
};

}  // namespace slamdunk
