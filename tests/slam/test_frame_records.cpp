// A session's frame records go through SessionLog's file: every field comes back bit for bit,
// so the trajectory written from them is the one computed.

#include <slamdunk/slam/SlamSystem.h>

#include <gtest/gtest.h>

using namespace slamdunk;

TEST(FrameRecords, ComeBackFromTheSessionFileBitForBit) {
  SessionLog<FrameRecord> log;
  const size_t n = 2 * SessionLog<FrameRecord>::kChunk + 3;
  std::vector<FrameRecord> written;
  for (size_t i = 0; i < n; ++i) {
    FrameRecord r;
    r.timestamp = 1700000000.0 + i / 30.0;
    r.status = i % 7 == 0 ? TrackingStatus::Lost : TrackingStatus::Tracked;
    r.reference = KeyframeId(i / 40);
    r.poseInReference =
        Pose(Eigen::AngleAxisd(0.001 * double(i), Eigen::Vector3d(1, 2, 3).normalized()));
    r.poseInReference.translation() = Eigen::Vector3d(std::sin(i), 1e-9 * i, -3.0 / (i + 1));
    written.push_back(r);
    log.push_back(r);
  }
  size_t i = 0;
  log.forEach([&](const FrameRecord& r) {
    ASSERT_LT(i, n);
    EXPECT_EQ(r.timestamp, written[i].timestamp);
    EXPECT_EQ(r.status, written[i].status);
    EXPECT_EQ(r.reference, written[i].reference);
    EXPECT_TRUE(r.poseInReference.matrix() == written[i].poseInReference.matrix()) << "frame " << i;
    ++i;
  });
  EXPECT_EQ(i, n);
}
