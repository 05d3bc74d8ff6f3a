#include <slamdunk/core/IniOptions.h>
#include <slamdunk/mapping/LocalMap.h>

#include <cmath>
#include <stdexcept>

namespace slamdunk {

void LocalMapOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                         const std::string& section) {
  loadIniKeys(*this, cfg, section);
  const SectionChecks require(section);
  require(windowSize > 0, "window_size must be > 0");
  require(windowShift >= 0, "window_shift must be >= 0");
  require(windowShiftAngle >= 0 && windowShiftAngle <= 180,
          "window_shift_angle must be in [0, 180]");
  require(handoverFrames >= 0, "pool_handover_frames must be >= 0");
  require(handoverFeaturesPerFrame > 0, "pool_handover_features_per_frame must be > 0");
  require(std::isfinite(compactBeyond), "compact_beyond must be a number");
  require(pool.neighbours >= 2, "knn_neighbours must be >= 2");
  require(pool.searchThreads >= 1, "search_threads must be >= 1");
  require(pool.bruteForceBelow >= 0, "pool_brute_force_below must be >= 0");
}

void LocalMapOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                       const std::string& section) const {
  saveIniKeys(*this, cfg, section);
}

}  // namespace slamdunk
