#include <slamdunk/core/PngHeader.h>

#include <cstring>
#include <fstream>

namespace slamdunk {

namespace {
constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

uint32_t bigEndian32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}
}  // namespace

bool looksLikePng(const uint8_t* data, size_t size) {
  return size >= 8 && std::memcmp(data, kSignature, 8) == 0;
}

std::optional<PngSize> pngSize(const uint8_t* data, size_t size) {
  // Signature (8), IHDR length (4) and type (4), then width and height (4 + 4, big-endian).
  if (size < 24 || !looksLikePng(data, size) || std::memcmp(data + 12, "IHDR", 4) != 0)
    return std::nullopt;
  return PngSize{bigEndian32(data + 16), bigEndian32(data + 20)};
}

std::optional<PngSize> pngFileSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  uint8_t head[24];
  if (!in.read(reinterpret_cast<char*>(head), sizeof head)) return std::nullopt;
  return pngSize(head, sizeof head);
}

}  // namespace slamdunk
