// slamdunk-rawlog: runs SlamDunk over a rawlog of CObservation3DRangeScan and writes the
// trajectory of every tracked frame (TUM format, optical frame), the keyframes' and the map
// products asked for. A command line over slamdunk::apps::RawlogSlamRun (modules/apps).

#include "RawlogCommandLine.h"
#include "RunWindow.h"

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/MemoryReuse.h>

#include <cstdio>
#include <iostream>

using namespace slamdunk;

int main(int argc, char** argv) {
  keepFreedMemoryForReuse();  // frames one after the other: their buffers' pages stay mapped
  try {
    RawlogCommandLine args;
    if (const auto exitCode = parseRawlogCommandLine(argc, argv, args)) return *exitCode;
    apps::RawlogSlamRun run(args.run);
    std::unique_ptr<RunWindow> window;
    if (args.gui) window = std::make_unique<RunWindow>(run, args.guiPaused, args.run.log);
    const apps::RawlogRunResult result = run.run();
    if (window) window->flush();  // the map after the last optimization
    apps::printRunSummary(result.figures, args.json);
    // Out now: stdout may be a pipe (fully buffered), and the summary must not depend on how
    // the viewer's window and the process end.
    std::fflush(stdout);
    if (window && args.guiWait) window->waitUntilClosed();
    if (result.readError.empty()) return 0;
    std::cerr << "slamdunk-rawlog: error: " << result.readError << "; the outputs cover the "
              << result.figures.decodeMs.size() << " frames before it\n";
    return 2;
  } catch (const TCLAP::ArgException& e) {
    std::cerr << "slamdunk-rawlog: " << e.error() << " (" << e.argId() << "); see --help\n";
  } catch (const std::exception& e) {
    std::cerr << "slamdunk-rawlog: error: " << e.what() << "\n";
  }
  return 1;
}
