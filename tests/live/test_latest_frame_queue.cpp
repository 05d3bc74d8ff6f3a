// The grabber-to-tracker hand-off: the oldest waiting frame is dropped and counted when full,
// frames come out in order, close() lets the consumer drain and then stop.

#include <slamdunk/live/LatestFrameQueue.h>

#include <gtest/gtest.h>
#include <mrpt/system/datetime.h>

#include <thread>

using mrpt::obs::CObservation3DRangeScan;
using slamdunk::live::LatestFrameQueue;

namespace {
CObservation3DRangeScan::Ptr frame(double t) {
  auto f = std::make_shared<CObservation3DRangeScan>();
  f->timestamp = mrpt::Clock::fromDouble(t);
  return f;
}
double stamp(const CObservation3DRangeScan::Ptr& f) { return mrpt::Clock::toDouble(f->timestamp); }
}  // namespace

TEST(LatestFrameQueue, DropsTheOldestWhenFullAndCountsIt) {
  LatestFrameQueue q(2);
  EXPECT_FALSE(q.push(frame(1)));
  EXPECT_FALSE(q.push(frame(2)));
  EXPECT_TRUE(q.push(frame(3)));  // 1 is dropped
  EXPECT_TRUE(q.push(frame(4)));  // 2 is dropped
  EXPECT_EQ(q.dropped(), 2u);
  EXPECT_EQ(stamp(q.pop()), 3);
  EXPECT_EQ(stamp(q.pop()), 4);
}

TEST(LatestFrameQueue, CapacityOneKeepsOnlyTheLatest) {
  LatestFrameQueue q(0);  // clamped to 1
  for (int i = 1; i <= 5; ++i) q.push(frame(i));
  EXPECT_EQ(q.dropped(), 4u);
  EXPECT_EQ(stamp(q.pop()), 5);
}

TEST(LatestFrameQueue, CloseDrainsThenReturnsNull) {
  LatestFrameQueue q(4);
  q.push(frame(1));
  q.push(frame(2));
  q.close();
  EXPECT_EQ(stamp(q.pop()), 1);
  EXPECT_EQ(stamp(q.pop()), 2);
  EXPECT_EQ(q.pop(), nullptr);
}

TEST(LatestFrameQueue, ConsumerWakesUpOnPushAndOnClose) {
  LatestFrameQueue q(8);
  std::vector<double> got;
  std::thread consumer([&] {
    while (auto f = q.pop()) got.push_back(stamp(f));
  });
  for (int i = 1; i <= 100; ++i) {
    q.push(frame(i));
    if (i % 10 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  q.close();
  consumer.join();  // would hang if close() did not wake the consumer
  // Whatever was not dropped arrives in order, and nothing is lost without being counted.
  EXPECT_EQ(got.size() + q.dropped(), 100u);
  EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), 100);  // the latest frame always gets through
}
