#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/IniOptions.h>
#include <slamdunk/core/TextParsing.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace slamdunk {

namespace {
std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}
}  // namespace

IniSectionReader::IniSectionReader(const mrpt::config::CConfigFileBase& cfg, std::string section)
    : cfg_(cfg), section_(std::move(section)) {}

void IniSectionReader::failChoice(const std::string& key, const std::string& name,
                                  const std::string& choices) const {
  throw std::invalid_argument("[" + section_ + "] " + key + " = '" + printableText(name) +
                              "' is not one of " + choices);
}

bool IniSectionReader::sectionExists() const { return cfg_.sectionExists(section_); }

std::string IniSectionReader::rawValue(const std::string& key, bool& found) {
  known_.insert(key);
  found = false;
  if (!cfg_.sectionExists(section_)) return {};
  std::vector<std::string> keys;
  cfg_.getAllKeys(section_, keys);
  found = std::find(keys.begin(), keys.end(), key) != keys.end();
  if (!found) return {};
  // MRPT strips trailing "//" comments; strip '#' and ';' ones too.
  std::string v = cfg_.read_string(section_, key, "", false);
  const size_t c = v.find_first_of("#;");
  if (c != std::string::npos) v = v.substr(0, c);
  return trimmed(v);
}

double IniSectionReader::readDouble(const std::string& key, double defaultValue) {
  bool found;
  const std::string v = rawValue(key, found);
  if (!found) return defaultValue;
  const std::optional<double> x = parseNumber(v);
  if (!x || !std::isfinite(*x))
    throw std::invalid_argument("[" + section_ + "] " + key + " = '" + printableText(v) +
                                "' is not a finite number");
  return *x;
}

int IniSectionReader::readInt(const std::string& key, int defaultValue) {
  bool found;
  const std::string v = rawValue(key, found);
  if (!found) return defaultValue;
  char* end = nullptr;
  const long x = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || end != v.c_str() + v.size() || x < INT32_MIN || x > INT32_MAX)
    throw std::invalid_argument("[" + section_ + "] " + key + " = '" + printableText(v) +
                                "' is not an integer");
  return static_cast<int>(x);
}

void IniSectionReader::operator()(const std::string& key, size_t& value) {
  const int count = readInt(key, static_cast<int>(value));
  if (count < 0)
    throw std::invalid_argument("[" + section_ + "] " + key + " = " + std::to_string(count) +
                                " is not a count (a whole number >= 0)");
  value = static_cast<size_t>(count);
}

bool IniSectionReader::readBool(const std::string& key, bool defaultValue) {
  bool found;
  const std::string v = lower(rawValue(key, found));
  if (!found) return defaultValue;
  if (v == "1" || v == "true" || v == "yes" || v == "on") return true;
  if (v == "0" || v == "false" || v == "no" || v == "off") return false;
  throw std::invalid_argument("[" + section_ + "] " + key + " = '" + printableText(v) +
                              "' is not a boolean (true/false)");
}

std::string IniSectionReader::readString(const std::string& key, const std::string& defaultValue) {
  bool found;
  const std::string v = rawValue(key, found);
  return found ? v : defaultValue;
}

std::vector<double> IniSectionReader::readDoubles(const std::string& key,
                                                  const std::vector<double>& defaultValue,
                                                  int expectedCount) {
  bool found;
  std::string v = rawValue(key, found);
  if (!found) return defaultValue;
  std::replace(v.begin(), v.end(), ',', ' ');
  for (char& c : v)
    if (c == '[' || c == ']') c = ' ';
  std::istringstream in(v);
  std::vector<double> out;
  std::string tok;
  while (in >> tok) {
    const std::optional<double> x = parseNumber(tok);
    if (!x || !std::isfinite(*x))
      throw std::invalid_argument("[" + section_ + "] " + key + ": '" + printableText(tok) +
                                  "' is not a finite number");
    out.push_back(*x);
  }
  if (expectedCount >= 0 && static_cast<int>(out.size()) != expectedCount)
    throw std::invalid_argument("[" + section_ + "] " + key + " needs " +
                                std::to_string(expectedCount) + " numbers, found " +
                                std::to_string(out.size()));
  return out;
}

void IniSectionReader::rejectUnknownKeys(
    const std::map<std::string, std::string>& movedKeys) const {
  if (!cfg_.sectionExists(section_)) return;
  std::vector<std::string> keys;
  cfg_.getAllKeys(section_, keys);
  for (const auto& k : keys)
    if (const auto moved = movedKeys.find(k); moved != movedKeys.end() && !known_.count(k))
      throw std::invalid_argument("[" + section_ + "] " + k + " now belongs to section [" +
                                  moved->second + "]: move it there");
  std::string unknown;
  for (const auto& k : keys)
    if (!known_.count(k)) unknown += (unknown.empty() ? "" : ", ") + printableText(k);
  if (unknown.empty()) return;
  std::string allowed;
  for (const auto& k : known_) allowed += (allowed.empty() ? "" : " ") + k;
  throw std::invalid_argument("unknown key(s) in section [" + section_ + "]: " + unknown +
                              " (known keys: " + allowed + ")");
}

}  // namespace slamdunk
