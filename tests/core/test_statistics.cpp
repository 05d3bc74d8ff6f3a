#include <slamdunk/core/Statistics.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace slamdunk;

TEST(Statistics, MedianOfOddAndEvenCounts) {
  EXPECT_EQ(median({3, 1, 2}), 2);
  EXPECT_EQ(median({4, 1, 3, 2}), 2.5);  // the mean of the middle two
  EXPECT_TRUE(std::isnan(median({})));
}

TEST(Statistics, UpperMedianIsAlwaysOneOfTheValues) {
  EXPECT_EQ(upperMedian({3, 1, 2}), 2);
  EXPECT_EQ(upperMedian({4, 1, 3, 2}), 3);
  EXPECT_TRUE(std::isnan(upperMedian({})));
}
