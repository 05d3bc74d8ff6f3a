#pragma once
// Plug-ins loaded on first use: a feature whose libraries are heavy (a GUI toolkit, PCL's I/O
// with VTK) lives in a shared library of its own, so that a process that never uses it does not
// load them.

#include <filesystem>
#include <string>
#include <vector>

namespace slamdunk {

/// Opens the first of `candidates` that exists and can be loaded, and returns the address of
/// its `symbol`. The library is never unloaded (RTLD_NODELETE): threads it starts and static
/// state it keeps may outlive its use. Throws std::runtime_error, starting with `what` (who
/// needs it), naming the paths tried and why each failed.
void* loadPluginSymbol(const std::vector<std::filesystem::path>& candidates, const char* symbol,
                       const std::string& what);

}  // namespace slamdunk
