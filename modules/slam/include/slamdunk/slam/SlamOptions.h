#pragma once
// The whole pipeline's parameters: one INI file with sections [features], [local_map],
// [tracker], [optimizer], [loop_closing] and [slam], each loaded by its own options struct, and
// [grid_map] for the occupancy grid made from the map. Unknown sections or keys are errors naming
// them; docs/parameters.md lists every key.

#include <slamdunk/features/FeatureExtractor.h>
#include <slamdunk/grid_map/GridMapOptions.h>
#include <slamdunk/loop_closing/LoopClosingOptions.h>
#include <slamdunk/optimization/LocalOptimizer.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <mrpt/config/CLoadableOptions.h>

#include <string>

namespace slamdunk {

struct SlamOptions : public mrpt::config::CLoadableOptions {
  FeatureOptions features;
  TrackerOptions tracker;
  LocalOptimizerOptions optimizer;
  LoopClosingOptions loopClosing;
  GridMapOptions gridMap;         ///< the occupancy grid the apps make from the map (--gridmap)
  bool localOptimization = true;  ///< run the relative BA when a keyframe is created
  bool optimizerThread = false;   ///< run it beside tracking (live use) instead of inline
  bool globalPassAtEnd = false;   ///< one optimization over the whole graph at the end

  /// Reads the sections of a pipeline INI; sections absent keep their defaults.
  /// Its own INI keys (section [slam]; each module's options have their own section).
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("local_optimization", o.localOptimization);
    k("optimizer_thread", o.optimizerThread);
    k("global_pass_at_end", o.globalPassAtEnd);
  }

  void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                          const std::string& sectionPrefix = "") override;
  void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                        const std::string& sectionPrefix = "") const override;
  /// Loads a file; throws std::runtime_error naming the file and the bad key or section.
  static SlamOptions fromFile(const std::string& path);
};

}  // namespace slamdunk
