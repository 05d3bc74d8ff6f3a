#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/PrefetchingRawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>

#include <stdexcept>

namespace slamdunk {

PrefetchingRawlogReader::PrefetchingRawlogReader(const std::string& path, size_t depth,
                                                 size_t firstScan)
    : reader_(path), scansToPass_(firstScan), prefetcher_([this] { return read(); }, depth) {}

std::optional<PrefetchingRawlogReader::Item> PrefetchingRawlogReader::read() {
  Item item;
  for (; scansToPass_ > 0; --scansToPass_)
    if (!reader_.next()) return std::nullopt;
  item.scan = reader_.next();
  if (!item.scan) return std::nullopt;
  try {
    loadExternalImages(*item.scan);
  } catch (const std::exception& e) {
    // Externally stored images: MRPT's error names the image, not the rawlog.
    throw std::runtime_error("rawlog '" + reader_.path() + "', entry " +
                             std::to_string(reader_.entriesRead() - 1) +
                             ": cannot load its external images: " + summarizeError(e.what()));
  }
  item.entriesRead = reader_.entriesRead();
  item.skipped = reader_.otherObservationsSkipped();
  return item;
}

mrpt::obs::CObservation3DRangeScan::Ptr PrefetchingRawlogReader::next() {
  std::optional<Item> item;
  try {
    item = prefetcher_.next();
  } catch (...) {
    // The reading thread has stopped at the error: the reader's counts are final.
    handedOut(reader_.entriesRead(), reader_.otherObservationsSkipped());
    throw;
  }
  if (!item) {
    handedOut(reader_.entriesRead(), reader_.otherObservationsSkipped());  // the end, as above
    return nullptr;
  }
  handedOut(item->entriesRead, item->skipped);
  return item->scan;
}

void PrefetchingRawlogReader::handedOut(size_t entriesRead, size_t skipped) {
  std::lock_guard lock(countsMutex_);
  entriesRead_ = entriesRead;
  skipped_ = skipped;
}

size_t PrefetchingRawlogReader::entriesRead() const {
  std::lock_guard lock(countsMutex_);
  return entriesRead_;
}

size_t PrefetchingRawlogReader::otherObservationsSkipped() const {
  std::lock_guard lock(countsMutex_);
  return skipped_;
}

}  // namespace slamdunk
