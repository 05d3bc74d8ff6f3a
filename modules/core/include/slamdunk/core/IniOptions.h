#pragma once
// Strict INI reading on top of MRPT's CConfigFileBase: every key has a default, and an unknown
// key or a malformed value is an error naming the section, the key and the value.

#include <mrpt/config/CConfigFileBase.h>

#include <cstdint>
#include <map>
#include <set>
#include <string>

namespace slamdunk {

/// Reads typed values from one section and remembers which keys it was asked for, so that
/// rejectUnknownKeys() can report a misspelled key instead of silently using a default.
class IniSectionReader {
 public:
  IniSectionReader(const mrpt::config::CConfigFileBase& cfg, std::string section);

  double readDouble(const std::string& key, double defaultValue);
  int readInt(const std::string& key, int defaultValue);
  bool readBool(const std::string& key, bool defaultValue);
  std::string readString(const std::string& key, const std::string& defaultValue);
  /// Numbers separated by spaces or commas; throws when the count differs from expectedCount
  /// (expectedCount < 0 accepts any count).
  std::vector<double> readDoubles(const std::string& key, const std::vector<double>& defaultValue,
                                  int expectedCount = -1);

  /// The visitor form of the reads above, for an options struct that lists its keys once
  /// (`forEachKey(options, visitor)`) and is loaded and saved through that list.
  void operator()(const std::string& key, double& value) { value = readDouble(key, value); }
  void operator()(const std::string& key, int& value) { value = readInt(key, value); }
  void operator()(const std::string& key, bool& value) { value = readBool(key, value); }
  void operator()(const std::string& key, std::string& value) { value = readString(key, value); }
  void operator()(const std::string& key, uint32_t& value) {
    value = static_cast<uint32_t>(readInt(key, static_cast<int>(value)));
  }
  /// An enumeration written as a name: `parse` turns the name into the value (and names the
  /// choices when it cannot), `toString(value)` the value into the name.
  template <class Enum, class Parse>
  void choice(const std::string& key, Enum& value, Parse parse) {
    value = parse(readString(key, toString(value)));
  }

  bool sectionExists() const;
  /// Throws std::invalid_argument listing the keys present in the section that were never read.
  /// `movedKeys` maps keys that once belonged to this section to the section they moved to:
  /// an old INI file then fails with a message naming where the key goes now.
  void rejectUnknownKeys(const std::map<std::string, std::string>& movedKeys = {}) const;
  const std::string& section() const { return section_; }

 private:
  std::string rawValue(const std::string& key, bool& found);
  const mrpt::config::CConfigFileBase& cfg_;
  std::string section_;
  std::set<std::string> known_;
};

/// Writes one section through the same key list as IniSectionReader reads it.
class IniSectionWriter {
 public:
  IniSectionWriter(mrpt::config::CConfigFileBase& cfg, std::string section)
      : cfg_(cfg), section_(std::move(section)) {}
  template <class T>
  void operator()(const std::string& key, const T& value) {
    cfg_.write(section_, key, value);
  }
  void operator()(const std::string& key, uint32_t value) {
    cfg_.write(section_, key, static_cast<int>(value));
  }
  template <class Enum, class Parse>
  void choice(const std::string& key, const Enum& value, Parse) {
    cfg_.write(section_, key, toString(value));
  }

 private:
  mrpt::config::CConfigFileBase& cfg_;
  std::string section_;
};

}  // namespace slamdunk
