#pragma once
// Sequential reader of the CObservation3DRangeScan entries of a rawlog (either rawlog format).

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <memory>
#include <string>

namespace slamdunk {

class RawlogReader {
 public:
  /// Opens the rawlog; throws std::runtime_error if missing or unreadable. Points MRPT's lazy-load
  /// base path at "<dir>/<name>_Images" so externally stored images are found.
  explicit RawlogReader(const std::string& path);
  ~RawlogReader();

  /// Next 3D range scan (other observation types are skipped and counted); nullptr at the end.
  /// Throws std::runtime_error naming the file and entry index on a truncated or corrupt file.
  mrpt::obs::CObservation3DRangeScan::Ptr next();

  size_t entriesRead() const { return entries_; }
  size_t otherObservationsSkipped() const { return skipped_; }
  const std::string& path() const { return path_; }
  /// "<dir>/<name>_Images" for a rawlog path (MRPT 2.5.8's own helper returns a wrong path).
  static std::string imagesDirectoryFor(const std::string& rawlogPath);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string path_;
  size_t entries_ = 0;
  size_t skipped_ = 0;
};

}  // namespace slamdunk
