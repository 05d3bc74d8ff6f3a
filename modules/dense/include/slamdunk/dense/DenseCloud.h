#pragma once
// A coloured point cloud with no PCL in sight: callers of the dense module (the apps, the
// renderer) never need PCL headers. Points are in the map's world frame, which is the first
// camera's optical frame (x right, y down, z forward), the same frame as the trajectories.

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace slamdunk {

struct DenseCloud {
  using Rgb = std::array<uint8_t, 3>;

  std::vector<Eigen::Vector3f> points;
  std::vector<Rgb> colours;  ///< red, green, blue; one per point

  size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  void reserve(size_t n) {
    points.reserve(n);
    colours.reserve(n);
  }
  void add(const Eigen::Vector3f& p, const Rgb& c) {
    points.push_back(p);
    colours.push_back(c);
  }
  void append(const DenseCloud& other);

  /// Axis-aligned bounding box of the points between the given quantiles on each axis
  /// (0 and 1 = the exact box; e.g. 0.01/0.99 ignores stray points). False when empty.
  bool boundingBox(Eigen::Vector3f& min, Eigen::Vector3f& max, double lowQuantile = 0.0,
                   double highQuantile = 1.0) const;
};

}  // namespace slamdunk
