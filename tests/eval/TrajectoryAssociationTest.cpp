#include <slamdunk/eval/TrajectoryAssociation.h>

#include <gtest/gtest.h>

#include <set>
#include <utility>
#include <vector>

using namespace slamdunk;
using namespace slamdunk::eval;

namespace {

Trajectory stamps(std::initializer_list<double> ts) {
  Trajectory t;
  for (double s : ts) t.push_back({s, Pose::Identity()});
  return t;
}

using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

/// The association's pairs as (gt, est) indices, in its order.
Pairs pairsOf(const TrajectoryAssociation& a) {
  Pairs out;
  for (const AssociatedPair& p : a.pairs) out.emplace_back(p.gt, p.est);
  return out;
}

}  // namespace

TEST(TrajectoryAssociation, WindowIsTwentyMillisecondsExclusive) {
  const TrajectoryAssociation a =
      TrajectoryAssociation::compute(stamps({1.0, 2.0}), stamps({1.015, 2.025}), 0.02);
  EXPECT_EQ(pairsOf(a), (Pairs{{0, 0}}));
  EXPECT_EQ(a.unmatchedEstimates, 1u);
  // Exactly max_difference apart is outside too (associate.py uses '<').
  EXPECT_TRUE(TrajectoryAssociation::compute(stamps({0.5}), stamps({0.5}), 0.0).pairs.empty());
}

// Estimated stamp 0.010 is closest to gt 0.012, and so is estimated stamp 0.022: a naive
// nearest-neighbour match would give gt 0.012 two partners. associate.py takes the globally
// smallest difference first (0.002) and then nothing else fits one-to-one within 0.02 s.
TEST(TrajectoryAssociation, GreedySmallestDifferenceIsOneToOne) {
  const TrajectoryAssociation a =
      TrajectoryAssociation::compute(stamps({0.000, 0.012}), stamps({0.010, 0.022}), 0.02);
  EXPECT_EQ(pairsOf(a), (Pairs{{1, 0}}));
  EXPECT_EQ(a.unmatchedEstimates, 1u);
}

// A chain where estimates 0.008 and 0.0095 both have gt 0.009 as nearest neighbour; greedy by
// smallest difference must still produce a one-to-one matching.
TEST(TrajectoryAssociation, OneToOneOnDenseChain) {
  const TrajectoryAssociation a = TrajectoryAssociation::compute(
      stamps({0.000, 0.009, 0.018, 0.027}), stamps({0.008, 0.0095, 0.019, 0.030}), 0.02);
  std::set<std::size_t> gtUsed, estUsed;
  for (const AssociatedPair& p : a.pairs) {
    EXPECT_TRUE(gtUsed.insert(p.gt).second) << "gt " << p.gt << " used twice";
    EXPECT_TRUE(estUsed.insert(p.est).second) << "est " << p.est << " used twice";
  }
  // Taken in this order: gt .009-est .0095 (0.0005), gt .018-est .019 (0.001), gt .027-est .030
  // (0.003), then est .008 can only go to gt .000 (0.008).
  EXPECT_EQ(pairsOf(a), (Pairs{{0, 0}, {1, 1}, {2, 2}, {3, 3}}));
}

TEST(TrajectoryAssociation, UnsortedInputSortedOutputAndOffset) {
  const TrajectoryAssociation a = TrajectoryAssociation::compute(
      stamps({3.0, 1.0, 2.0}), stamps({11.001, 13.0, 12.005, 50.0}), 0.02, -10.0);
  EXPECT_EQ(pairsOf(a), (Pairs{{1, 0}, {2, 2}, {0, 1}}));  // gt stamps 1.0, 2.0, 3.0
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
