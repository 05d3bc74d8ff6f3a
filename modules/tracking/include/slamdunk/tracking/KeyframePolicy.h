#pragma once
// Keyframe spawning by overlap (paper Sec. 4.2): the image is divided into N×M cells; a cell
// counts when it holds more than F matched inliers; spawn when the count falls below τ.

#include <opencv2/core/types.hpp>

#include <vector>

namespace slamdunk {

struct KeyframePolicyOptions {
  int gridCols = 4;           ///< N
  int gridRows = 4;           ///< M
  int minInliersPerCell = 1;  ///< F: a cell counts when it holds more than F inliers
  double minOverlap = 0.8;    ///< τ
  /// Count only cells where the frame itself has more than F features: a textureless part of
  /// the view (a white wall) can never overlap and would otherwise force a keyframe per frame.
  bool onlyTexturedCells = true;
  /// A cell is textured when the frame has at least this many features in it (and more than
  /// F). 0: more than F, the paper's reading.
  int texturedCellFeatures = 0;
  /// A frame the overlap would make a keyframe makes none when at least this share of its
  /// points is already seen, from nearly the same place, by a keyframe it matched (see
  /// ViewCoverage): keyframes follow the space covered, not the time spent in it. 0: off, the
  /// paper's rule.
  double coveredView = 0.95;

  /// Its INI keys (in [tracker]), listed once for IniSectionReader and IniSectionWriter.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("grid_cols", o.gridCols);
    k("grid_rows", o.gridRows);
    k("cell_min_inliers", o.minInliersPerCell);
    k("keyframe_overlap", o.minOverlap);
    k("only_textured_cells", o.onlyTexturedCells);
    k("textured_cell_features", o.texturedCellFeatures);
    k("keyframe_covered_view", o.coveredView);
  }
};

class KeyframePolicy {
 public:
  explicit KeyframePolicy(KeyframePolicyOptions options = {}) : options_(options) {}

  /// Fraction of (eligible) cells holding more than F inliers; `eligibleCells`, if given, gets
  /// how many cells counted.
  double overlap(const std::vector<cv::Point2f>& inlierPixels,
                 const std::vector<cv::Point2f>& allFeaturePixels, int width, int height,
                 int* eligibleCells = nullptr) const;
  bool shouldSpawn(double overlap) const { return overlap < options_.minOverlap; }
  const KeyframePolicyOptions& options() const { return options_; }

 private:
  KeyframePolicyOptions options_;
};

}  // namespace slamdunk
