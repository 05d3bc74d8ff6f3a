#pragma once
// Seeded byte-level mutations for the fuzz driver: the same seed gives the same inputs on every
// machine (own generator and arithmetic, no std:: distributions, whose results vary by library).

#include <cstdint>
#include <string>
#include <vector>

namespace slamdunk::fuzz {

using Bytes = std::vector<uint8_t>;

/// splitmix64: small, fast and fully specified.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next();
  /// Uniform in [0, n) (n > 0; the modulo bias is irrelevant here).
  uint64_t below(uint64_t n) { return next() % n; }
  bool chance(unsigned percent) { return below(100) < percent; }
  double uniform(double lo, double hi);

 private:
  uint64_t state_;
};

/// Values that make readers fail in interesting ways (zero, minus one, extremes, NaN, inf).
const std::vector<std::string>& interestingNumberTexts();
double interestingDouble(Rng& rng);

enum class InputKind { Binary, Text };

/// Applies 1-4 stacked mutations: bit flips, byte insert/delete/duplicate of ranges,
/// truncation, splicing with `other`, interesting integers and floats (as bytes for binary
/// inputs, as text for text inputs), and line-level edits for text.
void mutate(Bytes& data, const Bytes& other, InputKind kind, Rng& rng);

/// Rewrites the CRC of every chunk of a PNG so that a mutation reaches the decoder instead of
/// stopping at libpng's checksum test. Leaves anything that is not chunk-shaped alone.
void fixPngCrcs(Bytes& png);

}  // namespace slamdunk::fuzz
