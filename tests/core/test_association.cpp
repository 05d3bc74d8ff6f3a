#include <slamdunk/core/TimestampAssociation.h>

#include <gtest/gtest.h>

using namespace slamdunk;

TEST(TimestampAssociation, ThresholdIsStrict) {
  const auto p = associateTimestamps({1.0, 2.0}, {1.015, 2.025}, 0.02);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0], std::make_pair(size_t(0), size_t(0)));
}

TEST(TimestampAssociation, GreedyBySmallestDifferenceOneToOne) {
  // b[0] is nearest to both a[0] (0.010) and a[1] (0.004): a[1] gets it, a[0] falls back to b[1].
  const auto p = associateTimestamps({1.000, 1.014}, {1.010, 0.988}, 0.02);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0], std::make_pair(size_t(0), size_t(1)));
  EXPECT_EQ(p[1], std::make_pair(size_t(1), size_t(0)));
}

TEST(TimestampAssociation, UnsortedInputAndEmpty) {
  EXPECT_TRUE(associateTimestamps({}, {1.0}).empty());
  // Sorted by stamp: a = 1.0 (index 1) pairs with b = 1.001 (index 2), and so on.
  const auto p = associateTimestamps({3.0, 1.0, 2.0}, {2.001, 3.001, 1.001});
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0], std::make_pair(size_t(1), size_t(2)));
  EXPECT_EQ(p[1], std::make_pair(size_t(2), size_t(0)));
  EXPECT_EQ(p[2], std::make_pair(size_t(0), size_t(1)));
}
