// The dense cloud's PCL functions, from a plug-in loaded on first use: PCL's I/O library pulls
// in VTK, and a process that writes no cloud file (most runs, every robot app that only tracks)
// does not load them (about 30 MiB of its memory).

#include "PclCloudFunctions.h"

#include <slamdunk/core/Plugin.h>

#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>

namespace slamdunk {

namespace {
/// Beside this library, where the build and the install both put it.
const PclCloudFunctions& pclFunctions() {
  static const PclCloudFunctions* functions = [] {
    Dl_info self{};
    if (!dladdr(reinterpret_cast<void*>(&haveDenseFileOutputs), &self) || !self.dli_fname)
      throw std::runtime_error("dense outputs: cannot locate libslamdunk_dense");
    // PCL keeps static state for the process' life: the plug-in is never unloaded.
    using Entry = const PclCloudFunctions* (*)();
    const auto entry = reinterpret_cast<Entry>(
        loadPluginSymbol({std::filesystem::path(self.dli_fname).parent_path() / kPclCloudPlugin},
                         kPclCloudFunctionsSymbol, "dense outputs (PCL)"));
    return entry();
  }();
  return *functions;
}
}  // namespace

bool haveDenseFileOutputs() { return true; }

DenseCloud voxelFilter(const DenseCloud& cloud, double voxelSize) {
  return pclFunctions().voxelFilter(cloud, voxelSize);
}

void writePly(const DenseCloud& cloud, const std::string& path, bool ascii) {
  pclFunctions().writePly(cloud, path, ascii);
}

void writePcd(const DenseCloud& cloud, const std::string& path, bool ascii) {
  pclFunctions().writePcd(cloud, path, ascii);
}

DenseCloud readPointCloud(const std::string& path) { return pclFunctions().readPointCloud(path); }

}  // namespace slamdunk
