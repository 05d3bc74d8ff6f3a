#include <slamdunk/mapping/QuadTree.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace slamdunk;

TEST(QuadTree, SquareQueryEqualsBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-40, 60);  // beyond the initial root: it must grow
  QuadTree qt(4);
  std::vector<QuadTree::Item> items;
  for (uint32_t i = 0; i < 2000; ++i) {
    items.push_back({u(rng), u(rng), i});
    qt.insert(items.back().x, items.back().y, i);
  }
  EXPECT_EQ(qt.size(), 2000u);
  for (int q = 0; q < 50; ++q) {
    const double cx = u(rng), cy = u(rng), size = 1 + q;
    std::vector<uint32_t> expected;
    for (const auto& it : items)
      if (std::abs(it.x - cx) <= size / 2 && std::abs(it.y - cy) <= size / 2)
        expected.push_back(it.id);
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(qt.querySquare(cx, cy, size), expected) << "query " << q;
  }
}

TEST(QuadTree, RemoveAndReinsertMovesAnItem) {
  QuadTree qt;
  qt.insert(1, 1, 7);
  qt.insert(1, 1, 8);  // coincident points are fine
  EXPECT_EQ(qt.querySquare(1, 1, 0.5), (std::vector<uint32_t>{7, 8}));
  EXPECT_TRUE(qt.remove(1, 1, 7));
  EXPECT_FALSE(qt.remove(1, 1, 7));
  qt.insert(30, -20, 7);
  EXPECT_EQ(qt.querySquare(1, 1, 0.5), (std::vector<uint32_t>{8}));
  EXPECT_EQ(qt.querySquare(30, -20, 5), (std::vector<uint32_t>{7}));
  EXPECT_EQ(qt.size(), 2u);
}

TEST(QuadTree, ManyCoincidentPointsDoNotRecurseForever) {
  QuadTree qt(2);
  for (uint32_t i = 0; i < 100; ++i) qt.insert(0.5, 0.5, i);
  EXPECT_EQ(qt.querySquare(0.5, 0.5, 0.1).size(), 100u);
  EXPECT_THROW(qt.insert(std::nan(""), 0, 1), std::invalid_argument);
}
