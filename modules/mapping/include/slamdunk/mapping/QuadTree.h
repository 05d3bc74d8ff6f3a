#pragma once
// Point quadtree over keyframe positions on the ground-parallel plane (paper Sec. 4.1, Fig. 3).
// Grows its root as points arrive outside it, so no workspace size must be known in advance.

#include <cstdint>
#include <memory>
#include <vector>

namespace slamdunk {

class QuadTree {
 public:
  struct Item {
    double x, y;
    uint32_t id;
  };

  explicit QuadTree(size_t nodeCapacity = 8);
  ~QuadTree();

  void insert(double x, double y, uint32_t id);
  /// Removes the item with this id at (x, y); false if not found.
  bool remove(double x, double y, uint32_t id);
  /// Ids of the items inside the axis-aligned square of side `size` centred at (cx, cy),
  /// sorted ascending.
  std::vector<uint32_t> querySquare(double cx, double cy, double size) const;
  size_t size() const { return count_; }
  void clear();

 private:
  struct Node;
  void growToContain(double x, double y);

  size_t capacity_;
  size_t count_ = 0;
  std::unique_ptr<Node> root_;
};

}  // namespace slamdunk
