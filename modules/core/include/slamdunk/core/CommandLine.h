#pragma once
// What every command-line tool shares: parsing, the error line and exit code, progress lines.
// MRPT's bundled TCLAP does not exit on --help or on a bad option: parse() prints and returns
// false, and a tool that ignored it would go on with default values. parseCommandLine() turns
// that into an exit code.

#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <functional>
#include <iostream>
#include <optional>
#include <string>

namespace slamdunk {

/// Empty when the tool should run; otherwise the exit code (0 after --help/--version).
inline std::optional<int> parseCommandLine(TCLAP::CmdLine& cmd, int argc, char** argv,
                                           const std::string& tool) {
  if (cmd.parse(argc, argv)) return std::nullopt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help" || a == "--version") return 0;
  }
  std::cerr << tool << ": bad command line; see " << tool << " --help\n";
  return 1;
}

/// A tool's main: runs body() and returns its exit code; an exception becomes one line on
/// stderr naming the tool ("<tool>: error: ...") and exit code 1.
template <class Body>
int runTool(const std::string& tool, Body&& body) {
  try {
    return body();
  } catch (const TCLAP::ArgException& e) {
    std::cerr << tool << ": " << e.error() << " (" << e.argId() << "); see --help\n";
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
  }
  return 1;
}

/// A progress(done, total) callback for a long run over frames: "<label> done/total frames
/// (p%)" on stderr about every 5 % and at the end. Empty (no output) when quiet.
inline std::function<void(size_t, size_t)> frameProgress(std::string label, bool quiet) {
  if (quiet) return {};
  return [label = std::move(label), lastReported = size_t(0)](size_t done, size_t total) mutable {
    if (done == total || done - lastReported >= std::max<size_t>(1, total / 20)) {
      std::fprintf(stderr, "%s %zu/%zu frames (%.0f%%)\n", label.c_str(), done, total,
                   100.0 * done / total);
      lastReported = done;
    }
  };
}

}  // namespace slamdunk
