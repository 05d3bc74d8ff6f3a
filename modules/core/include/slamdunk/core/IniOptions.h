#pragma once
// Strict INI reading on top of MRPT's CConfigFileBase: every key has a default, and an unknown
// key or a malformed value is an error naming the section, the key and the value.

#include <slamdunk/core/EnumNames.h>

#include <mrpt/config/CConfigFileBase.h>

#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

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
  void operator()(const std::string& key, float& value) {
    value = static_cast<float>(readDouble(key, value));
  }
  void operator()(const std::string& key, int& value) { value = readInt(key, value); }
  void operator()(const std::string& key, bool& value) { value = readBool(key, value); }
  void operator()(const std::string& key, std::string& value) { value = readString(key, value); }
  /// A count: a whole number >= 0.
  void operator()(const std::string& key, size_t& value);
  void operator()(const std::string& key, uint32_t& value) {
    value = static_cast<uint32_t>(readInt(key, static_cast<int>(value)));
  }
  /// An enumeration is written as one of its names (core/EnumNames.h); a name not in its
  /// table is an error listing the choices.
  template <class Enum, class = std::enable_if_t<std::is_enum_v<Enum>>>
  void operator()(const std::string& key, Enum& value) {
    const std::string name = readString(key, toString(value));
    const std::optional<Enum> named = enumFromName<Enum>(name);
    if (!named) failChoice(key, name, enumChoices<Enum>());
    value = *named;
  }

  bool sectionExists() const;
  /// Throws std::invalid_argument listing the keys present in the section that were never read.
  /// `movedKeys` maps keys that once belonged to this section to the section they moved to:
  /// an old INI file then fails with a message naming where the key goes now.
  void rejectUnknownKeys(const std::map<std::string, std::string>& movedKeys = {}) const;
  const std::string& section() const { return section_; }

 private:
  std::string rawValue(const std::string& key, bool& found);
  [[noreturn]] void failChoice(const std::string& key, const std::string& name,
                               const std::string& choices) const;
  const mrpt::config::CConfigFileBase& cfg_;
  std::string section_;
  std::set<std::string> known_;
};

/// The checks an options struct makes on its values once loaded: a failed one is an error
/// naming the section, as in "[local_map] window_size must be > 0".
class SectionChecks {
 public:
  explicit SectionChecks(std::string section) : section_(std::move(section)) {}
  void operator()(bool ok, const std::string& what) const {
    if (!ok) throw std::invalid_argument("[" + section_ + "] " + what);
  }

 private:
  std::string section_;
};

/// Writes one section through the same key list as IniSectionReader reads it.
class IniSectionWriter {
 public:
  IniSectionWriter(mrpt::config::CConfigFileBase& cfg, std::string section)
      : cfg_(cfg), section_(std::move(section)) {}
  template <class T>
  void operator()(const std::string& key, const T& value) {
    if constexpr (std::is_enum_v<T>)
      cfg_.write(section_, key, std::string(toString(value)));
    else
      cfg_.write(section_, key, value);
  }
  void operator()(const std::string& key, uint32_t value) {
    cfg_.write(section_, key, static_cast<int>(value));
  }

 private:
  mrpt::config::CConfigFileBase& cfg_;
  std::string section_;
};

// An options struct lists its keys once, as a static member template
//   template <class Self, class Keys> static void forEachKey(Self& o, Keys& k) {
//     k("window_size", o.windowSize);  ...
//   }
// and is loaded, saved and named through that list.

/// Reads the keys Options::forEachKey lists from `section`; a key in the section that the list
/// does not hold is an error (`movedKeys`: see IniSectionReader::rejectUnknownKeys).
template <class Options>
void loadIniKeys(Options& options, const mrpt::config::CConfigFileBase& cfg,
                 const std::string& section,
                 const std::map<std::string, std::string>& movedKeys = {}) {
  IniSectionReader reader(cfg, section);
  Options::forEachKey(options, reader);
  reader.rejectUnknownKeys(movedKeys);
}

template <class Options>
void saveIniKeys(const Options& options, mrpt::config::CConfigFileBase& cfg,
                 const std::string& section) {
  IniSectionWriter writer(cfg, section);
  Options::forEachKey(options, writer);
}

/// Collects the names of the keys a key list visits.
struct IniKeyNames {
  std::vector<std::string> names;
  template <class T>
  void operator()(const std::string& key, const T&) {
    names.push_back(key);
  }
};

/// The names of the keys Options::forEachKey lists, in its order.
template <class Options>
std::vector<std::string> iniKeyNames() {
  IniKeyNames names;
  const Options defaults;
  Options::forEachKey(defaults, names);
  return names.names;
}

}  // namespace slamdunk
