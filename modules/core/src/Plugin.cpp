#include <slamdunk/core/Plugin.h>

#include <dlfcn.h>

#include <stdexcept>

namespace slamdunk {

void* loadPluginSymbol(const std::vector<std::filesystem::path>& candidates, const char* symbol,
                       const std::string& what) {
  std::string tried;
  for (const std::filesystem::path& path : candidates) {
    if (!std::filesystem::exists(path)) {
      tried += "; '" + path.string() + "' not found";
      continue;
    }
    void* plugin = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!plugin) {
      tried += std::string("; ") + dlerror();
      continue;
    }
    if (void* address = dlsym(plugin, symbol)) return address;
    tried += "; '" + path.string() + "' has no " + symbol;
    dlclose(plugin);
  }
  throw std::runtime_error(what + ": cannot load its plug-in" + tried);
}

}  // namespace slamdunk
