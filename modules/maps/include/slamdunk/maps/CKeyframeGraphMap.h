#pragma once
// CONTRACT (written by the lead; the implementer may add members but must keep these).
// The SlamDunk map as an MRPT metric map plug-in: keyframes (pose, timestamp, features with 3D
// points and descriptors, optionally images), graph edges with their matches. Serializable
// (versioned) and declarable in a CMultiMetricMap INI as "slamdunk::CKeyframeGraphMap".

#include <slamdunk/graph/KeyframeGraph.h>

#include <mrpt/maps/CMetricMap.h>

#include <memory>
#include <string>

namespace slamdunk {

class CKeyframeGraphMap : public mrpt::maps::CMetricMap {
  DEFINE_SERIALIZABLE(CKeyframeGraphMap, slamdunk)

 public:
  CKeyframeGraphMap();
  /// Shares the graph (no copy): the map shows what the SLAM system is building.
  explicit CKeyframeGraphMap(std::shared_ptr<KeyframeGraph> graph);

  const std::shared_ptr<KeyframeGraph>& graph() const;
  void setGraph(std::shared_ptr<KeyframeGraph> graph);

  /// Writes the map (gz-compressed MRPT serialization) atomically: an existing file is
  /// replaced only on success.
  void saveToFile(const std::string& path) const;
  /// Reads a map; throws std::runtime_error naming the file on a missing, corrupt or truncated
  /// file, or one written by a newer version of this class.
  static std::shared_ptr<CKeyframeGraphMap> loadFromFile(const std::string& path);

  // ... CMetricMap overrides, MAP_DEFINITION_START/END options (see the implementation)
};

}  // namespace slamdunk
