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

// The tracker revises the frames it registered before the camera's readout was learned: their
// records, the newest before the current frame's, get the new poses; the rest stay as they were.
TEST(FrameRecords, RevisedFramesReplaceTheirRecordsOnly) {
  SessionLog<FrameRecord> log;
  const size_t n = SessionLog<FrameRecord>::kChunk + 10;  // one chunk in the file, ten in memory
  auto stamp = [](size_t i) { return 100.0 + i / 30.0; };
  for (size_t i = 0; i < n; ++i) {
    FrameRecord r;
    r.timestamp = stamp(i);
    r.status = TrackingStatus::Tracked;
    r.poseInReference.translation() = Eigen::Vector3d(double(i), 0, 0);
    log.push_back(r);
  }
  Pose moved = Pose::Identity();
  moved.translation() = Eigen::Vector3d(0, 0, 1);
  // Two frames before the newest, a stamp that is not there, and one gone to the file.
  std::vector<TrackingResult::RevisedFrame> revised{{stamp(n - 4), 7, moved},
                                                    {stamp(n - 3), 7, moved}};
  EXPECT_EQ(reviseFrameRecords(log, revised), 2u);
  EXPECT_EQ(reviseFrameRecords(log, {{stamp(n - 2) + 0.001, 7, moved}}), 0u);
  EXPECT_EQ(reviseFrameRecords(log, {{stamp(3), 7, moved}}), 0u);
  size_t i = 0;
  log.forEach([&](const FrameRecord& r) {
    const bool revisedHere = i == n - 4 || i == n - 3;
    EXPECT_EQ(r.reference, revisedHere ? 7u : 0u) << "frame " << i;
    EXPECT_EQ(r.poseInReference.translation(),
              revisedHere ? moved.translation() : Eigen::Vector3d(double(i), 0, 0))
        << "frame " << i;
    ++i;
  });
  EXPECT_EQ(i, n);
}
