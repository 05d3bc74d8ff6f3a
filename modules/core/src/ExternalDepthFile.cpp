#include <slamdunk/core/ExternalDepthFile.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/system/filesystem.h>

#include <libdeflate.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

namespace slamdunk {

namespace {
std::vector<uint8_t> readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return {};
  std::vector<uint8_t> bytes(static_cast<size_t>(std::max<std::streamoff>(0, in.tellg())));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())))
    return {};
  return bytes;
}

uint32_t littleEndian32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

bool hostIsLittleEndian() {
  const uint16_t one = 1;
  uint8_t first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

/// One per thread, kept: depth files are loaded on the read-ahead threads, frame after frame, and
/// a decompressor may not be shared between threads.
libdeflate_decompressor* threadDecompressor() {
  thread_local std::unique_ptr<libdeflate_decompressor, decltype(&libdeflate_free_decompressor)>
      decompressor(libdeflate_alloc_decompressor(), &libdeflate_free_decompressor);
  return decompressor.get();
}

/// The largest image accepted: a damaged header must not make us allocate gigabytes.
constexpr size_t kMaxPixels = size_t(8192) * 8192;
}  // namespace

bool loadExternalDepthFile(const mrpt::obs::CObservation3DRangeScan& obs) {
  if (!obs.hasRangeImage || !obs.rangeImage_isExternallyStored() || obs.rangeImage.rows() != 0 ||
      !obs.rangeImageOtherLayers.empty() || !hostIsLittleEndian())
    return false;
  const std::string path = obs.rangeImage_getExternalStorageFileAbsolutePath({});
  if (mrpt::system::extractFileExtension(path, true) != "bin") return false;
  const std::vector<uint8_t> file = readWholeFile(path);
  // gzip's trailer holds the inflated size (modulo 2^32), the header two magic bytes.
  if (file.size() < 18 || file[0] != 0x1f || file[1] != 0x8b) return false;
  const size_t inflatedSize = littleEndian32(file.data() + file.size() - 4);
  if (inflatedSize < 8 || inflatedSize > 8 + 2 * kMaxPixels) return false;
  std::vector<uint8_t> data(inflatedSize);

  libdeflate_decompressor* inflater = threadDecompressor();
  if (!inflater) return false;
  size_t inflated = 0;
  if (libdeflate_gzip_decompress(inflater, file.data(), file.size(), data.data(), data.size(),
                                 &inflated) != LIBDEFLATE_SUCCESS ||
      inflated != data.size())
    return false;
  // Rawlogs older than MRPT's version 9 hold a serialized float matrix instead, whose size never
  // equals rows x cols 16-bit values after the two counts.
  const uint32_t rows = littleEndian32(data.data()), cols = littleEndian32(data.data() + 4);
  if (rows == 0 || cols == 0 || size_t(rows) * cols > kMaxPixels ||
      data.size() != 8 + 2 * size_t(rows) * cols)
    return false;

  // Loading fills a const observation, as MRPT's own load() does.
  auto& loaded = const_cast<mrpt::obs::CObservation3DRangeScan&>(obs);
  loaded.rangeImage_setSize(static_cast<int>(rows), static_cast<int>(cols));
  std::memcpy(loaded.rangeImage.data(), data.data() + 8, data.size() - 8);
  return true;
}

}  // namespace slamdunk
