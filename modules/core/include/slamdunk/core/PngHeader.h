#pragma once
// The size a PNG declares in its header, read before decoding: a corrupt header can declare an
// image of up to 2^31 x 2^31 pixels, and decoders allocate the whole image before they find
// that the data is missing. Readers compare the declared size with the size they expect first.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace slamdunk {

struct PngSize {
  uint32_t width = 0, height = 0;
};

/// True when the bytes start with the PNG signature.
bool looksLikePng(const uint8_t* data, size_t size);
/// Width and height from the IHDR chunk; empty when the data is not a PNG or is too short.
std::optional<PngSize> pngSize(const uint8_t* data, size_t size);
/// The same for a file (reads its first 24 bytes); empty when not a PNG or unreadable.
std::optional<PngSize> pngFileSize(const std::string& path);

}  // namespace slamdunk
