#include "RunWindow.h"

#include <slamdunk/core/Plugin.h>

#include <filesystem>
#include <vector>

namespace slamdunk {

namespace {
/// Beside the program in the build tree, in <libdir>/slamdunk once installed.
std::vector<std::filesystem::path> pluginCandidates() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path dir = ec ? std::filesystem::path(".") : exe.parent_path();
  return {dir / SLAMDUNK_RUN_WINDOW_PLUGIN,
          dir / ".." / SLAMDUNK_INSTALL_LIBDIR / "slamdunk" / SLAMDUNK_RUN_WINDOW_PLUGIN};
}
}  // namespace

RunWindow::RunWindow(apps::RawlogSlamRun& run, bool paused,
                     std::function<void(const std::string&)> log) {
  // Never unloaded: MRPT's GUI thread, which outlives the window, may still run its code.
  const auto open = reinterpret_cast<OpenRunWindowFunction>(
      loadPluginSymbol(pluginCandidates(), kOpenRunWindowSymbol,
                       "--gui (the viewer; a build without X11 has none)"));
  backend_.reset(open(run, paused, std::move(log)));
}

RunWindow::~RunWindow() = default;

}  // namespace slamdunk
