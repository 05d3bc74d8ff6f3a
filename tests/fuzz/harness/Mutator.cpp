#include "Mutator.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

namespace slamdunk::fuzz {

uint64_t Rng::next() {
  uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double Rng::uniform(double lo, double hi) {
  return lo + (hi - lo) * (double(next() >> 11) / double(uint64_t(1) << 53));
}

const std::vector<std::string>& interestingNumberTexts() {
  static const std::vector<std::string> v{"0",          "-0",         "-1",
                                          "1",          "2147483647", "-2147483648",
                                          "4294967295", "2147483648", "1e308",
                                          "1e309",      "-1e309",     "1e-320",
                                          "nan",        "NaN",        "-nan",
                                          "inf",        "-inf",       "Infinity",
                                          "0x10",       "1e",         ".",
                                          "-",          "+",          "",
                                          "65535",      "65536",      "99999999999999999999",
                                          "3.4e38",     "1.5e-45"};
  return v;
}

double interestingDouble(Rng& rng) {
  static const double v[] = {0.0,
                             -0.0,
                             -1.0,
                             1.0,
                             std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::lowest(),
                             std::numeric_limits<double>::denorm_min(),
                             1e-300,
                             1e300,
                             65535.0,
                             2147483648.0};
  return v[rng.below(sizeof v / sizeof v[0])];
}

namespace {

size_t pos(Rng& rng, size_t size) { return size ? size_t(rng.below(size)) : 0; }

/// Short ranges are the common case: a length field or a single value.
size_t rangeLength(Rng& rng, size_t maxLen) {
  if (maxLen == 0) return 0;
  const size_t cap = rng.chance(80) ? std::min<size_t>(maxLen, 16) : maxLen;
  return 1 + size_t(rng.below(cap));
}

void overwrite(Bytes& d, size_t at, const void* src, size_t n) {
  if (d.size() < n) return;
  at = std::min(at, d.size() - n);
  std::memcpy(d.data() + at, src, n);
}

void insertText(Bytes& d, size_t at, const std::string& s) {
  d.insert(d.begin() + std::min(at, d.size()), s.begin(), s.end());
}

/// Offsets [begin, end) of the number-like tokens of a text (digits, signs, dots, exponents).
std::vector<std::pair<size_t, size_t>> numberTokens(const Bytes& d) {
  std::vector<std::pair<size_t, size_t>> out;
  auto isNum = [](uint8_t c) {
    return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E';
  };
  for (size_t i = 0; i < d.size();) {
    if (d[i] >= '0' && d[i] <= '9') {
      size_t b = i, e = i;
      while (b > 0 && isNum(d[b - 1])) --b;
      while (e < d.size() && isNum(d[e])) ++e;
      out.emplace_back(b, e);
      i = e;
    } else {
      ++i;
    }
  }
  return out;
}

std::vector<std::pair<size_t, size_t>> lines(const Bytes& d) {
  std::vector<std::pair<size_t, size_t>> out;
  size_t b = 0;
  for (size_t i = 0; i < d.size(); ++i)
    if (d[i] == '\n') {
      out.emplace_back(b, i + 1);
      b = i + 1;
    }
  if (b < d.size()) out.emplace_back(b, d.size());
  return out;
}

void mutateOnce(Bytes& d, const Bytes& other, InputKind kind, Rng& rng) {
  const bool text = kind == InputKind::Text;
  // Text inputs get mostly token- and line-level edits; binary ones mostly byte-level ones.
  const unsigned op =
      text && rng.chance(60) ? 100 + unsigned(rng.below(6)) : unsigned(rng.below(10));
  switch (op) {
    case 0:  // flip one bit
      if (!d.empty()) d[pos(rng, d.size())] ^= uint8_t(1u << rng.below(8));
      break;
    case 1: {  // set a byte to a random or boundary value
      static const uint8_t v[] = {0, 1, 0x7f, 0x80, 0xff, '\n', ' ', '0', '-', '[', '='};
      if (!d.empty())
        d[pos(rng, d.size())] = rng.chance(50) ? uint8_t(rng.next()) : v[rng.below(sizeof v)];
      break;
    }
    case 2: {  // insert random bytes
      const size_t at = pos(rng, d.size() + 1), n = 1 + size_t(rng.below(16));
      Bytes ins(n);
      for (auto& b : ins) b = uint8_t(rng.next());
      d.insert(d.begin() + at, ins.begin(), ins.end());
      break;
    }
    case 3: {  // delete a range
      if (d.empty()) break;
      const size_t at = pos(rng, d.size()), n = rangeLength(rng, d.size() - at);
      d.erase(d.begin() + at, d.begin() + at + n);
      break;
    }
    case 4: {  // duplicate a range somewhere else
      if (d.empty() || d.size() > (1u << 22)) break;
      const size_t at = pos(rng, d.size()), n = rangeLength(rng, d.size() - at);
      const Bytes copy(d.begin() + at, d.begin() + at + n);
      const size_t to = pos(rng, d.size() + 1);
      d.insert(d.begin() + to, copy.begin(), copy.end());
      break;
    }
    case 5:  // truncate
      if (!d.empty()) d.resize(pos(rng, d.size()));
      break;
    case 6: {  // splice: our head, the other input's tail
      if (other.empty()) break;
      const size_t cut = pos(rng, d.size() + 1), from = pos(rng, other.size());
      d.resize(cut);
      d.insert(d.end(), other.begin() + from, other.end());
      break;
    }
    case 7: {  // an interesting integer (little-endian) over 1, 2, 4 or 8 bytes
      static const uint64_t v[] = {
          0,          1,          0xff,       0x7fff,         0xffff,
          0x7fffffff, 0x80000000, 0xffffffff, 0x100000000ULL, 0x7fffffffffffffffULL,
          ~0ULL,      1u << 20};
      const uint64_t x = rng.chance(70) ? v[rng.below(sizeof v / sizeof v[0])] : rng.next();
      const size_t width = size_t(1) << rng.below(4);
      if (text) {
        insertText(d, pos(rng, d.size() + 1), std::to_string(x));
      } else {
        uint8_t b[8];
        for (int k = 0; k < 8; ++k) b[k] = uint8_t(x >> (8 * k));
        overwrite(d, pos(rng, d.size()), b, width);
      }
      break;
    }
    case 8: {  // an interesting float or double (NaN, inf, extremes)
      const double x = interestingDouble(rng);
      if (text) {
        insertText(d, pos(rng, d.size() + 1), std::to_string(x));
      } else if (rng.chance(50)) {
        const float f = float(x);
        overwrite(d, pos(rng, d.size()), &f, sizeof f);
      } else {
        overwrite(d, pos(rng, d.size()), &x, sizeof x);
      }
      break;
    }
    case 9: {  // copy a chunk of the other input over ours
      if (other.empty() || d.empty()) break;
      const size_t from = pos(rng, other.size()), n = rangeLength(rng, other.size() - from);
      overwrite(d, pos(rng, d.size()), other.data() + from, std::min(n, d.size()));
      break;
    }
    case 100: {  // replace a number with an interesting one
      const auto toks = numberTokens(d);
      const auto& v = interestingNumberTexts();
      const std::string s = v[rng.below(v.size())];
      if (toks.empty()) {
        insertText(d, pos(rng, d.size() + 1), s);
        break;
      }
      const auto [b, e] = toks[rng.below(toks.size())];
      d.erase(d.begin() + b, d.begin() + e);
      insertText(d, b, s);
      break;
    }
    case 101: {  // insert a token with meaning to INI / list parsers
      static const char* v[] = {
          "#",     ";",    "//",           "=",          " = ",        "[",
          "]",     "\n",   "\r\n",         "\t",         ",",          " ",
          "[x]\n", "[]\n", "${A}",         "$eval{1/0}", "$env{HOME}", "@define A 1\n",
          "\"",    "\\",   "\xef\xbb\xbf", "\x00"};
      const size_t k = rng.below(sizeof v / sizeof v[0]);
      const std::string s = k + 1 == sizeof v / sizeof v[0] ? std::string(1, '\0') : v[k];
      insertText(d, pos(rng, d.size() + 1), s);
      break;
    }
    case 102: {  // duplicate a line
      const auto ls = lines(d);
      if (ls.empty()) break;
      const auto [b, e] = ls[rng.below(ls.size())];
      const Bytes copy(d.begin() + b, d.begin() + e);
      const auto [tb, te] = ls[rng.below(ls.size())];
      (void)te;
      d.insert(d.begin() + tb, copy.begin(), copy.end());
      break;
    }
    case 103: {  // delete a line
      const auto ls = lines(d);
      if (ls.empty()) break;
      const auto [b, e] = ls[rng.below(ls.size())];
      d.erase(d.begin() + b, d.begin() + e);
      break;
    }
    case 104: {  // swap two lines
      const auto ls = lines(d);
      if (ls.size() < 2) break;
      auto a = ls[rng.below(ls.size())], b = ls[rng.below(ls.size())];
      if (a.first > b.first) std::swap(a, b);
      if (a.first == b.first) break;
      Bytes out(d.begin(), d.begin() + a.first);
      out.insert(out.end(), d.begin() + b.first, d.begin() + b.second);
      out.insert(out.end(), d.begin() + a.second, d.begin() + b.first);
      out.insert(out.end(), d.begin() + a.first, d.begin() + a.second);
      out.insert(out.end(), d.begin() + b.second, d.end());
      d = std::move(out);
      break;
    }
    case 105: {  // a line of the other input inserted here
      const auto ls = lines(other);
      if (ls.empty()) break;
      const auto [b, e] = ls[rng.below(ls.size())];
      const auto mine = lines(d);
      const size_t at = mine.empty() ? 0 : mine[rng.below(mine.size())].first;
      d.insert(d.begin() + at, other.begin() + b, other.begin() + e);
      break;
    }
    default:
      break;
  }
}

}  // namespace

void mutate(Bytes& data, const Bytes& other, InputKind kind, Rng& rng) {
  const unsigned n = 1 + unsigned(rng.below(4));
  for (unsigned k = 0; k < n; ++k) mutateOnce(data, other, kind, rng);
}

namespace {
uint32_t crc32(const uint8_t* p, size_t n) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; ++i) c = table[(c ^ p[i]) & 0xff] ^ (c >> 8);
  return c ^ 0xffffffffu;
}
}  // namespace

void fixPngCrcs(Bytes& png) {
  size_t at = 8;  // after the signature
  while (at + 12 <= png.size()) {
    const uint32_t len = uint32_t(png[at]) << 24 | uint32_t(png[at + 1]) << 16 |
                         uint32_t(png[at + 2]) << 8 | uint32_t(png[at + 3]);
    if (len > png.size() - at - 12) return;
    const uint32_t c = crc32(png.data() + at + 4, size_t(len) + 4);
    uint8_t* out = png.data() + at + 8 + len;
    out[0] = uint8_t(c >> 24);
    out[1] = uint8_t(c >> 16);
    out[2] = uint8_t(c >> 8);
    out[3] = uint8_t(c);
    at += size_t(len) + 12;
  }
}

}  // namespace slamdunk::fuzz
