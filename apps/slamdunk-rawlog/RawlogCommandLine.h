#pragma once
// slamdunk-rawlog's command line: what to run, as the options of apps::RawlogSlamRun, and how
// to show it (summary as JSON, progress, the window).

#include <slamdunk/apps/RawlogSlamRun.h>

#include <optional>

namespace slamdunk {

struct RawlogCommandLine {
  apps::RawlogRunOptions run;  ///< its log prints to stderr unless --quiet
  bool json = false, quiet = false;
  bool noOptimization = false, mapImages = false;  ///< already applied to run.slam
  bool localize = false, extendMap = false;        ///< already applied to run.slam
  bool gui = false, guiWait = false, guiPaused = false;
};

/// Fills `out` from the arguments; returns the exit code when the program is to end now
/// (--help, a bad command line). Throws std::runtime_error for options that do not go together
/// or a bad pipeline INI.
std::optional<int> parseRawlogCommandLine(int argc, char** argv, RawlogCommandLine& out);

}  // namespace slamdunk
