#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/TextParsing.h>

#include <cstdio>
#include <sstream>
#include <vector>

namespace slamdunk {

std::string printableText(const std::string& s, size_t maxLength) {
  std::string out;
  for (unsigned char c : s) {
    if (out.size() >= maxLength) return out + "...";
    if (c >= 0x20 && c < 0x7f) {
      out += char(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    }
  }
  return out;
}

std::string summarizeError(const std::string& what) {
  static const std::string kBanner = "==== MRPT exception ====";
  static const std::string kParsing = "Exception while parsing typed object '";
  std::istringstream in(what);
  std::string line, first, innermost;
  std::vector<std::string> classes;
  bool inTrace = false;
  while (std::getline(in, line)) {
    line = trimmed(line);
    if (line.empty()) continue;
    if (line == kBanner) {
      inTrace = false;
      continue;
    }
    if (line.rfind("Call stack backtrace:", 0) == 0 || line.rfind("Location:", 0) == 0) {
      inTrace = true;
      continue;
    }
    if (inTrace || line.rfind("Original exception:", 0) == 0) continue;
    if (line.rfind("Message:", 0) == 0) line = trimmed(line.substr(8));
    if (line.rfind(kParsing, 0) == 0) {
      const size_t end = line.find('\'', kParsing.size());
      classes.push_back(line.substr(kParsing.size(), end - kParsing.size()));
      continue;
    }
    if (first.empty()) first = line;
    innermost = line;  // nested MRPT exceptions: the last message is the original cause
  }
  if (what.find(kBanner) == std::string::npos) innermost = first;
  std::string out;
  if (!classes.empty()) {
    out = "in ";
    for (size_t k = 0; k < classes.size(); ++k) out += (k ? " > " : "") + classes[k];
    out += ": ";
  }
  out += innermost.empty() ? "unknown error" : innermost;
  return printableText(out, 2000);
}

}  // namespace slamdunk
