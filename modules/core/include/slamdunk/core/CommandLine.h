#pragma once
// Command-line parsing shared by every tool. MRPT's bundled TCLAP does not exit on --help or on
// a bad option: parse() prints and returns false, and a tool that ignored it would go on with
// default values. parseCommandLine() turns that into an exit code.

#include <mrpt/3rdparty/tclap/CmdLine.h>

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

}  // namespace slamdunk
