#pragma once
// Reading the plain-text files of the TUM RGB-D tools (trajectories, image lists) and the
// numbers in INI values.

#include <cstdlib>
#include <istream>
#include <optional>
#include <string>

namespace slamdunk {

/// The number `text` spells, when all of it does ("inf" and "nan" included: callers that need
/// a finite value check it).
inline std::optional<double> parseNumber(const std::string& text) {
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) return std::nullopt;
  return x;
}

/// `text` without the blanks (spaces, tabs, line ends) at either end.
inline std::string trimmed(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
}

/// Calls fn(line, lineNumber) for each line of `in` that holds data, counting lines from 1:
/// blank lines and comments (lines whose first non-blank character is '#') are passed over.
template <class Fn>
void forEachDataLine(std::istream& in, Fn&& fn) {
  std::string line;
  size_t lineNumber = 0;
  while (std::getline(in, line)) {
    ++lineNumber;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    fn(line, lineNumber);
  }
}

}  // namespace slamdunk
