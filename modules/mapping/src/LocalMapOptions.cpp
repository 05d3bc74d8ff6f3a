#include <slamdunk/core/IniOptions.h>
#include <slamdunk/mapping/LocalMap.h>

#include <stdexcept>

namespace slamdunk {

namespace {
template <class Self, class Keys>
void forEachKey(Self& o, Keys& k) {
  k("window_size", o.windowSize);
  k("window_shift", o.windowShift);
  k("window_shift_angle", o.windowShiftAngle);
  k("pool_in_background", o.backgroundPreparation);
  k("pool_handover_frames", o.handoverFrames);
  k("pool_handover_features_per_frame", o.handoverFeaturesPerFrame);
  FeaturePoolOptions::forEachKey(o.pool, k);
}

/// Collects the key names of a key list.
struct KeyNames {
  std::vector<std::string> names;
  template <class T>
  void operator()(const std::string& key, const T&) {
    names.push_back(key);
  }
  template <class T, class Parse>
  void choice(const std::string& key, const T&, Parse) {
    names.push_back(key);
  }
};
}  // namespace

void LocalMapOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                         const std::string& section) {
  IniSectionReader r(cfg, section);
  forEachKey(*this, r);
  r.rejectUnknownKeys();
  auto require = [&](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument("[" + section + "] " + what);
  };
  require(windowSize > 0, "window_size must be > 0");
  require(windowShift >= 0, "window_shift must be >= 0");
  require(windowShiftAngle >= 0 && windowShiftAngle <= 180,
          "window_shift_angle must be in [0, 180]");
  require(handoverFrames >= 0, "pool_handover_frames must be >= 0");
  require(handoverFeaturesPerFrame > 0, "pool_handover_features_per_frame must be > 0");
  require(pool.neighbours >= 2, "knn_neighbours must be >= 2");
  require(pool.searchThreads >= 1, "search_threads must be >= 1");
  require(pool.bruteForceBelow >= 0, "pool_brute_force_below must be >= 0");
}

void LocalMapOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                       const std::string& section) const {
  IniSectionWriter w(cfg, section);
  forEachKey(*this, w);
}

std::vector<std::string> LocalMapOptions::keyNames() {
  KeyNames k;
  const LocalMapOptions defaults;
  forEachKey(defaults, k);
  return k.names;
}

}  // namespace slamdunk
