#pragma once
// Strict INI reading on top of MRPT's CConfigFileBase: every key has a default, and an unknown
// key or a malformed value is an error naming the section, the key and the value.

#include <mrpt/config/CConfigFileBase.h>

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

  bool sectionExists() const;
  /// Throws std::invalid_argument listing the keys present in the section that were never read.
  void rejectUnknownKeys() const;
  const std::string& section() const { return section_; }

 private:
  std::string rawValue(const std::string& key, bool& found);
  const mrpt::config::CConfigFileBase& cfg_;
  std::string section_;
  std::set<std::string> known_;
};

}  // namespace slamdunk
