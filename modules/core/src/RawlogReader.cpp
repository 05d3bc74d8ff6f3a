#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/RawlogReader.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/lazy_load_path.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <deque>
#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk {

struct RawlogReader::Impl {
  mrpt::io::CFileGZInputStream file;
  std::unique_ptr<mrpt::serialization::CArchive> archive;
  std::deque<mrpt::obs::CObservation::Ptr> pending;  // from a CSensoryFrame
};

std::string RawlogReader::imagesDirectoryFor(const std::string& rawlogPath) {
  const fs::path p(rawlogPath);
  return (p.parent_path() / (p.stem().string() + "_Images")).string();
}

RawlogReader::RawlogReader(const std::string& path) : impl_(std::make_unique<Impl>()), path_(path) {
  if (!fs::exists(path)) throw std::runtime_error("rawlog '" + path + "' does not exist");
  if (fs::is_directory(path)) throw std::runtime_error("rawlog '" + path + "' is a folder");
  if (!impl_->file.open(path)) throw std::runtime_error("cannot open rawlog '" + path + "'");
  impl_->archive =
      std::make_unique<mrpt::serialization::CArchiveStreamBase<mrpt::io::CFileGZInputStream>>(
          impl_->file);
  // Externally stored images are named relative to this folder (process-global in MRPT).
  mrpt::io::setLazyLoadPathBase(imagesDirectoryFor(path));
}

RawlogReader::~RawlogReader() = default;

mrpt::obs::CObservation3DRangeScan::Ptr RawlogReader::next() {
  using mrpt::obs::CObservation3DRangeScan;
  for (;;) {
    while (!impl_->pending.empty()) {
      auto obs = impl_->pending.front();
      impl_->pending.pop_front();
      if (auto scan = std::dynamic_pointer_cast<CObservation3DRangeScan>(obs)) return scan;
      ++skipped_;
    }
    const uint64_t before = impl_->file.getPosition();
    mrpt::serialization::CSerializable::Ptr object;
    try {
      object = impl_->archive->ReadObject();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      if (impl_->file.getPosition() == before) return nullptr;  // clean end between entries
      throw std::runtime_error("rawlog '" + path_ + "' is truncated: entry " +
                               std::to_string(entries_) + " ends early");
    } catch (const std::exception& e) {
      // MRPT's text nests one banner and stack trace per object being parsed: one line instead.
      throw std::runtime_error("rawlog '" + path_ + "' is corrupt or truncated at entry " +
                               std::to_string(entries_) + ": " + summarizeError(e.what()));
    }
    ++entries_;
    if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(object)) {
      for (const auto& o : *sf) impl_->pending.push_back(o);
    } else if (auto obs = std::dynamic_pointer_cast<mrpt::obs::CObservation>(object)) {
      impl_->pending.push_back(obs);
    } else if (!std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(object)) {
      ++skipped_;
    }
  }
}

}  // namespace slamdunk
