#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/IniOptions.h>
#include <slamdunk/slam/SlamOptions.h>

#include <mrpt/config/CConfigFile.h>

#include <filesystem>
#include <set>
#include <stdexcept>

namespace slamdunk {

namespace {
const std::set<std::string> kSections{"features",     "local_map", "tracker", "optimizer",
                                      "loop_closing", "grid_map",  "slam"};
}

void SlamOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                     const std::string& prefix) {
  std::vector<std::string> sections;
  cfg.getAllSections(sections);
  for (const auto& s : sections)
    if (!s.empty() && s.rfind(prefix, 0) == 0 && !kSections.count(s.substr(prefix.size())))
      throw std::invalid_argument(
          "unknown section [" + printableText(s) +
          "] (known: features, local_map, tracker, optimizer, loop_closing, grid_map, slam)");
  features.loadFromConfigFile(cfg, prefix + "features");
  tracker.localMap.loadFromConfigFile(cfg, prefix + "local_map");
  tracker.loadFromConfigFile(cfg, prefix + "tracker");
  optimizer.loadFromConfigFile(cfg, prefix + "optimizer");
  loopClosing.loadFromConfigFile(cfg, prefix + "loop_closing");
  gridMap.loadFromConfigFile(cfg, prefix + "grid_map");
  loadIniKeys(*this, cfg, prefix + "slam");
}

void SlamOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                   const std::string& prefix) const {
  features.saveToConfigFile(cfg, prefix + "features");
  tracker.localMap.saveToConfigFile(cfg, prefix + "local_map");
  tracker.saveToConfigFile(cfg, prefix + "tracker");
  optimizer.saveToConfigFile(cfg, prefix + "optimizer");
  loopClosing.saveToConfigFile(cfg, prefix + "loop_closing");
  gridMap.saveToConfigFile(cfg, prefix + "grid_map");
  saveIniKeys(*this, cfg, prefix + "slam");
}

SlamOptions SlamOptions::fromFile(const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error("configuration file '" + path + "' does not exist");
  SlamOptions o;
  try {
    // Inside the try: MRPT's parser itself throws on some malformed files (e.g. "${X}" naming
    // an undefined variable), and that error must name the file too.
    mrpt::config::CConfigFile cfg(path);
    o.loadFromConfigFile(cfg, "");
  } catch (const std::exception& e) {
    throw std::runtime_error("configuration file '" + path + "': " + summarizeError(e.what()));
  }
  return o;
}

}  // namespace slamdunk
