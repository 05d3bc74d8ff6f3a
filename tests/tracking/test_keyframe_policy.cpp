#include <slamdunk/tracking/KeyframePolicy.h>

#include <gtest/gtest.h>

using namespace slamdunk;

namespace {
std::vector<cv::Point2f> pointsInCells(const std::vector<int>& cells, int perCell) {
  std::vector<cv::Point2f> pts;
  for (int c : cells)
    for (int k = 0; k < perCell; ++k)
      pts.emplace_back((c % 4) * 160 + 10 + k, (c / 4) * 120 + 10 + k);
  return pts;
}
}  // namespace

TEST(KeyframePolicy, CountsCellsWithMoreThanFInliers) {
  KeyframePolicyOptions o;  // N = M = 4, F = 1, τ = 0.8
  o.onlyTexturedCells = false;
  KeyframePolicy policy(o);
  std::vector<int> all(16);
  for (int i = 0; i < 16; ++i) all[i] = i;
  const auto features = pointsInCells(all, 5);
  // 13 cells with 2 inliers (> F) and 3 with exactly 1 (= F, not counted): 13/16 = 0.8125.
  std::vector<int> thirteen(all.begin(), all.begin() + 13), rest(all.begin() + 13, all.end());
  auto inl = pointsInCells(thirteen, 2);
  for (auto& p : pointsInCells(rest, 1)) inl.push_back(p);
  EXPECT_DOUBLE_EQ(policy.overlap(inl, features, 640, 480), 13.0 / 16);
  EXPECT_FALSE(policy.shouldSpawn(13.0 / 16));
  // 12 of 16 = 0.75 < τ: spawn.
  std::vector<int> twelve(all.begin(), all.begin() + 12);
  const double o12 = policy.overlap(pointsInCells(twelve, 2), features, 640, 480);
  EXPECT_DOUBLE_EQ(o12, 0.75);
  EXPECT_TRUE(policy.shouldSpawn(o12));
}

TEST(KeyframePolicy, TexturelessCellsAreNotHeldAgainstTheFrame) {
  KeyframePolicy policy;  // onlyTexturedCells = true
  const std::vector<int> textured{0, 1, 2, 3, 4, 5, 6, 7};
  const auto features = pointsInCells(textured, 5);
  EXPECT_DOUBLE_EQ(policy.overlap(pointsInCells(textured, 2), features, 640, 480), 1.0);
  EXPECT_DOUBLE_EQ(policy.overlap({}, features, 640, 480), 0.0);
}
