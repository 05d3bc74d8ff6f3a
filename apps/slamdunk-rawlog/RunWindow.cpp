#include "RunWindow.h"

#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>
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
  std::string tried;
  for (const std::filesystem::path& path : pluginCandidates()) {
    if (!std::filesystem::exists(path)) continue;
    // Never unloaded: MRPT's GUI thread, which outlives the window, may still run its code.
    plugin_ = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (plugin_) break;
    tried += std::string("; ") + dlerror();
  }
  if (!plugin_)
    throw std::runtime_error(std::string("--gui: no viewer plug-in ") + SLAMDUNK_RUN_WINDOW_PLUGIN +
                             " beside the program (a build without slamdunk::viewer, which "
                             "needs X11)" +
                             tried);
  const auto open = reinterpret_cast<OpenRunWindowFunction>(dlsym(plugin_, kOpenRunWindowSymbol));
  if (!open) {
    dlclose(plugin_);
    throw std::runtime_error(std::string("--gui: ") + SLAMDUNK_RUN_WINDOW_PLUGIN + " has no " +
                             kOpenRunWindowSymbol);
  }
  backend_.reset(open(run, paused, std::move(log)));
}

RunWindow::~RunWindow() = default;

}  // namespace slamdunk
