#pragma once
// What an options struct says about an INI it refuses.

#include <mrpt/config/CConfigFileMemory.h>

#include <stdexcept>
#include <string>

namespace slamdunk::test {

/// The message Options::loadFromConfigFile throws (std::invalid_argument) on `iniText`, or ""
/// when it loads.
template <class Options>
std::string loadError(const std::string& iniText, const std::string& section) {
  mrpt::config::CConfigFileMemory cfg(iniText);
  Options options;
  try {
    options.loadFromConfigFile(cfg, section);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace slamdunk::test
