#include <slamdunk/eval/TrajectoryAssociation.h>

#include <gtest/gtest.h>

#include <set>

using namespace slamdunk;
using namespace slamdunk::eval;

namespace {

Trajectory stamps(std::initializer_list<double> ts) {
  Trajectory t;
  for (double s : ts) t.push_back({s, Pose::Identity()});
  return t;
}

}  // namespace

TEST(TrajectoryAssociation, WindowIsTwentyMillisecondsExclusive) {
  const Trajectory gt = stamps({1.0, 2.0});
  const Trajectory est = stamps({1.015, 2.025});
  const TrajectoryAssociation a = TrajectoryAssociation::compute(gt, est, 0.02);
  ASSERT_EQ(a.pairs.size(), 1u);
  EXPECT_EQ(a.pairs[0].gt, 0u);
  EXPECT_EQ(a.pairs[0].est, 0u);
  EXPECT_EQ(a.unmatchedEstimates, 1u);
  // Exactly max_difference apart is outside too (associate.py uses '<').
  EXPECT_TRUE(TrajectoryAssociation::compute(stamps({0.5}), stamps({0.5}), 0.0).pairs.empty());
}

// Estimated stamp 0.010 is closest to gt 0.012, and so is estimated stamp 0.022: a naive
// nearest-neighbour match would give gt 0.012 two partners. associate.py takes the globally
// smallest difference first (0.002) and then nothing else fits one-to-one within 0.02 s.
TEST(TrajectoryAssociation, GreedySmallestDifferenceIsOneToOne) {
  const Trajectory gt = stamps({0.000, 0.012});
  const Trajectory est = stamps({0.010, 0.022});
  const TrajectoryAssociation a = TrajectoryAssociation::compute(gt, est, 0.02);
  ASSERT_EQ(a.pairs.size(), 1u);
  EXPECT_EQ(a.pairs[0].gt, 1u);
  EXPECT_EQ(a.pairs[0].est, 0u);
  EXPECT_EQ(a.unmatchedEstimates, 1u);
}

// A chain where estimates 0.008 and 0.0095 both have gt 0.009 as nearest neighbour; greedy by
// smallest difference must still produce a one-to-one matching.
TEST(TrajectoryAssociation, OneToOneOnDenseChain) {
  const Trajectory gt = stamps({0.000, 0.009, 0.018, 0.027});
  const Trajectory est = stamps({0.008, 0.0095, 0.019, 0.030});
  const TrajectoryAssociation a = TrajectoryAssociation::compute(gt, est, 0.02);
  std::set<std::size_t> gtUsed, estUsed;
  for (const AssociatedPair& p : a.pairs) {
    EXPECT_TRUE(gtUsed.insert(p.gt).second) << "gt " << p.gt << " used twice";
    EXPECT_TRUE(estUsed.insert(p.est).second) << "est " << p.est << " used twice";
  }
  // Taken in this order: gt .009-est .0095 (0.0005), gt .018-est .019 (0.001), gt .027-est .030
  // (0.003), then est .008 can only go to gt .000 (0.008).
  ASSERT_EQ(a.pairs.size(), 4u);
  EXPECT_EQ(a.pairs[0].gt, 0u);
  EXPECT_EQ(a.pairs[0].est, 0u);
  EXPECT_EQ(a.pairs[1].gt, 1u);
  EXPECT_EQ(a.pairs[1].est, 1u);
  EXPECT_EQ(a.pairs[2].gt, 2u);
  EXPECT_EQ(a.pairs[2].est, 2u);
  EXPECT_EQ(a.pairs[3].gt, 3u);
  EXPECT_EQ(a.pairs[3].est, 3u);
}

TEST(TrajectoryAssociation, UnsortedInputSortedOutputAndOffset) {
  const Trajectory gt = stamps({3.0, 1.0, 2.0});
  const Trajectory est = stamps({11.001, 13.0, 12.005, 50.0});
  const TrajectoryAssociation a = TrajectoryAssociation::compute(gt, est, 0.02, -10.0);
  ASSERT_EQ(a.pairs.size(), 3u);
  EXPECT_EQ(a.pairs[0].gt, 1u);  // stamp 1.0
  EXPECT_EQ(a.pairs[0].est, 0u);
  EXPECT_EQ(a.pairs[1].gt, 2u);  // stamp 2.0
  EXPECT_EQ(a.pairs[1].est, 2u);
  EXPECT_EQ(a.pairs[2].gt, 0u);  // stamp 3.0
  EXPECT_EQ(a.pairs[2].est, 1u);
  EXPECT_EQ(a.unmatchedEstimates, 1u);
}

TEST(TrajectoryAssociation, SortedUniqueKeepsLastOfRepeatedStamp) {
  Trajectory t = stamps({2.0, 1.0, 2.0});
  t[0].pose.translation().x() = 5;
  t[2].pose.translation().x() = 7;
  std::size_t dropped = 0;
  const Trajectory u = sortedUniqueByStamp(t, &dropped);
  ASSERT_EQ(u.size(), 2u);
  EXPECT_EQ(dropped, 1u);
  EXPECT_EQ(u[0].timestamp, 1.0);
  EXPECT_EQ(u[1].timestamp, 2.0);
  EXPECT_EQ(u[1].pose.translation().x(), 7);
}
