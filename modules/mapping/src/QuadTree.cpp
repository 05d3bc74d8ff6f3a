#include <slamdunk/mapping/QuadTree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace slamdunk {

struct QuadTree::Node {
  double cx, cy, half;  // square cell: centre and half side
  std::vector<Item> items;
  std::array<std::unique_ptr<Node>, 4> children;

  Node(double x, double y, double h) : cx(x), cy(y), half(h) {}
  bool isLeaf() const { return !children[0]; }
  bool contains(double x, double y) const {
    return x >= cx - half && x < cx + half && y >= cy - half && y < cy + half;
  }
  int quadrant(double x, double y) const { return (x >= cx ? 1 : 0) + (y >= cy ? 2 : 0); }
  void split() {
    const double h = half / 2;
    for (int q = 0; q < 4; ++q)
      children[q] = std::make_unique<Node>(cx + ((q & 1) ? h : -h), cy + ((q & 2) ? h : -h), h);
  }
};

QuadTree::QuadTree(size_t nodeCapacity) : capacity_(std::max<size_t>(1, nodeCapacity)) {
  root_ = std::make_unique<Node>(0.0, 0.0, 8.0);
}

QuadTree::~QuadTree() = default;

void QuadTree::clear() {
  root_ = std::make_unique<Node>(0.0, 0.0, 8.0);
  count_ = 0;
}

void QuadTree::growToContain(double x, double y) {
  // Double the root towards the point until it fits; the old root becomes one quadrant.
  while (!root_->contains(x, y)) {
    const double h = root_->half;
    const double ncx = root_->cx + (x >= root_->cx ? h : -h);
    const double ncy = root_->cy + (y >= root_->cy ? h : -h);
    auto bigger = std::make_unique<Node>(ncx, ncy, 2 * h);
    bigger->split();
    const int q = bigger->quadrant(root_->cx, root_->cy);
    bigger->children[q] = std::move(root_);
    root_ = std::move(bigger);
  }
}

void QuadTree::insert(double x, double y, uint32_t id) {
  if (!std::isfinite(x) || !std::isfinite(y))
    throw std::invalid_argument("QuadTree::insert: non-finite position");
  growToContain(x, y);
  Node* n = root_.get();
  for (;;) {
    if (n->isLeaf()) {
      // Tiny cells stop splitting so coincident points cannot recurse forever.
      if (n->items.size() < capacity_ || n->half < 1e-6) {
        n->items.push_back({x, y, id});
        ++count_;
        return;
      }
      n->split();
      for (const Item& it : n->items) n->children[n->quadrant(it.x, it.y)]->items.push_back(it);
      n->items.clear();
    }
    n = n->children[n->quadrant(x, y)].get();
  }
}

bool QuadTree::remove(double x, double y, uint32_t id) {
  Node* n = root_.get();
  if (!n->contains(x, y)) return false;
  while (!n->isLeaf()) n = n->children[n->quadrant(x, y)].get();
  auto it = std::find_if(n->items.begin(), n->items.end(),
                         [&](const Item& i) { return i.id == id && i.x == x && i.y == y; });
  if (it == n->items.end()) return false;
  n->items.erase(it);
  --count_;
  return true;
}

std::vector<uint32_t> QuadTree::querySquare(double cx, double cy, double size) const {
  const double h = size / 2;
  std::vector<uint32_t> out;
  std::vector<const Node*> stack{root_.get()};
  while (!stack.empty()) {
    const Node* n = stack.back();
    stack.pop_back();
    if (std::abs(n->cx - cx) > n->half + h || std::abs(n->cy - cy) > n->half + h) continue;
    if (n->isLeaf()) {
      for (const Item& it : n->items)
        if (std::abs(it.x - cx) <= h && std::abs(it.y - cy) <= h) out.push_back(it.id);
    } else {
      for (const auto& c : n->children) stack.push_back(c.get());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace slamdunk
