#pragma once
// The SlamDunk map as an MRPT metric map plug-in: keyframes (pose, timestamp, features with 3D
// points and descriptors, optionally images), graph edges with their matches. Serializable
// (versioned) and declarable in a CMultiMetricMap INI as "slamdunk::CKeyframeGraphMap".
//
// Frames: the graph's world is the first keyframe's OPTICAL frame (x right, y down, z forward).
// getVisualizationInto() wraps everything in a CSetOfObjects posed with opticalInSensor(), so
// MRPT viewers see the world as the first camera's MRPT sensor frame (x forward, y left, z up).
//
// CMultiMetricMap INI (class names accepted: "slamdunk::CKeyframeGraphMap", "keyframeGraphMap"):
//   [map]
//   keyframeGraphMap_count = 1
//   [map_keyframeGraphMap_00_renderOpts]     ; optional, see TRenderOptions
//   cloud_decimation = 4
//
// File format (saveToFile): gz-compressed MRPT archive holding one object of this class at
// serialization version kSerializationVersion; older versions are read too (each version's
// layout: src/KeyframeGraphCodec.cpp). Images are kept exactly: colour as PNG (lossless); depth
// bit-exact, as a 16-bit PNG with a float scale when every pixel is float(k) * scale (checked
// when saving: sensor depth usually is), else as the raw CV_32F bytes.

#include <slamdunk/graph/KeyframeGraph.h>

#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/maps/CMetricMap.h>

#include <memory>
#include <string>

namespace slamdunk {

class CKeyframeGraphMap : public mrpt::maps::CMetricMap {
  DEFINE_SERIALIZABLE(CKeyframeGraphMap, slamdunk)

 public:
  /// Newest serialization version this build writes and reads (2: descriptors may be 8-bit
  /// codes, 3: half floats, which builds reading older versions would take for a corrupt file).
  static constexpr uint8_t kSerializationVersion = 3;

  CKeyframeGraphMap();
  /// Shares the graph (no copy): the map shows what the SLAM system is building. The map never
  /// modifies its graph in place (clear() and deserialization swap in a new one), so copies
  /// (clone()) simply share it too.
  explicit CKeyframeGraphMap(std::shared_ptr<KeyframeGraph> graph);

  const std::shared_ptr<KeyframeGraph>& graph() const;
  void setGraph(std::shared_ptr<KeyframeGraph> graph);

  /// Writes the map (gz-compressed MRPT serialization) atomically: an existing file is
  /// replaced only on success.
  void saveToFile(const std::string& path) const;
  /// The same with a gzip level: 0 (stored, no compression: about 10x less CPU, files 1.5x
  /// larger; live checkpoints use it) to 9. The one-argument form uses 1 (fastest compression).
  void saveToFile(const std::string& path, int compressionLevel) const;
  /// Reads a map; throws std::runtime_error naming the file on a missing, corrupt or truncated
  /// file, or one written by a newer version of this class.
  static std::shared_ptr<CKeyframeGraphMap> loadFromFile(const std::string& path);

  /// How getVisualizationInto() draws the map. INI section "<prefix>_renderOpts".
  struct TRenderOptions : public mrpt::config::CLoadableOptions {
    int cloudDecimation = 4;   ///< use every n-th pixel in rows and columns of keyframe depth
    float maxDepth = 4.0f;     ///< metres; farther (noisier) depth pixels are not drawn
    float pointSize = 2.0f;    ///< pixels
    bool showPoints = true;    ///< dense cloud if images are kept, else feature points
    bool showFrustums = true;  ///< one camera frustum per keyframe
    bool showEdges = true;     ///< lines between the centres of matched keyframes
    float frustumSize = 0.1f;  ///< metres from the camera centre to the frustum's far plane

    /// Its INI keys (section <map>_renderOpts), listed once for loading and saving.
    template <class Self, class Keys>
    static void forEachKey(Self& o, Keys& k) {
      k("cloud_decimation", o.cloudDecimation);
      k("max_depth", o.maxDepth);
      k("point_size", o.pointSize);
      k("show_points", o.showPoints);
      k("show_frustums", o.showFrustums);
      k("show_edges", o.showEdges);
      k("frustum_size", o.frustumSize);
    }

    void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                            const std::string& section) override;
    void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                          const std::string& section) const override;
  };
  TRenderOptions renderOptions;

  MAP_DEFINITION_START(CKeyframeGraphMap)
  TRenderOptions renderOptions;
  MAP_DEFINITION_END(CKeyframeGraphMap)

  // --- CMetricMap interface
  bool isEmpty() const override;
  /// Keyframes, edges, matches and how many keyframes carry images.
  std::string asString() const override;
  void getVisualizationInto(mrpt::opengl::CSetOfObjects& o) const override;
  /// Writes "<prefix>.3Dscene" (gz-compressed COpenGLScene of the visualization).
  void saveMetricMapRepresentationToFile(const std::string& prefix) const override;
  /// The map's 3D points as drawn (world = first camera's MRPT sensor frame, z up): the dense
  /// cloud when images are kept, else the feature points. Rebuilt on every call.
  const mrpt::maps::CSimplePointsMap* getAsSimplePointsMap() const override;

 private:
  void internal_clear() override;
  /// Keyframes are added by the SLAM system (see CSlamDunkMapBuilder): always returns false.
  bool internal_insertObservation(
      const mrpt::obs::CObservation& obs,
      const std::optional<const mrpt::poses::CPose3D>& robotPose = std::nullopt) override;
  /// Not supported: returns 0 (canComputeObservationLikelihood() says false).
  double internal_computeObservationLikelihood(
      const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3D& takenFrom) const override;
  bool internal_canComputeObservationLikelihood(const mrpt::obs::CObservation& obs) const override;

  std::shared_ptr<KeyframeGraph> graph_;
  mutable std::shared_ptr<mrpt::maps::CSimplePointsMap> pointsCache_;
};

/// The class registers itself when libslamdunk_mrpt_map is loaded. A program that uses the map only
/// by name (CMultiMetricMap INI, CArchive::ReadObject) references none of the library's symbols,
/// so Debian's default `--as-needed` drops the library from the executable. Calling this once
/// (it registers the class again, harmlessly) keeps it; `-Wl,--no-as-needed` works too.
void registerKeyframeGraphMap();

}  // namespace slamdunk
