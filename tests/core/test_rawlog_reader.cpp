#include <slamdunk/core/RawlogReader.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <filesystem>
#include <fstream>

using namespace slamdunk;

namespace {
mrpt::obs::CObservation3DRangeScan::Ptr scanAt(double t) {
  auto obs = mrpt::obs::CObservation3DRangeScan::Create();
  obs->timestamp = mrpt::Clock::fromDouble(t);
  obs->hasRangeImage = true;
  obs->rangeImage_setSize(24, 32);
  obs->rangeImage.fill(1234);
  obs->hasIntensityImage = true;
  obs->intensityImage.resize(32, 24, mrpt::img::CH_RGB);
  return obs;
}

std::string writeRawlog(const std::string& path, bool sensoryFrames) {
  mrpt::io::CFileGZOutputStream f(path);
  auto a = mrpt::serialization::archiveFrom(f);
  for (int i = 0; i < 3; ++i) {
    if (sensoryFrames) {
      mrpt::obs::CSensoryFrame sf;
      sf.insert(scanAt(i));
      a << sf;
    } else {
      a << *scanAt(i);
      mrpt::obs::CObservationOdometry odo;  // some other sensor, to be skipped
      a << odo;
    }
  }
  return path;
}
}  // namespace

TEST(RawlogReader, ReadsObservationOnlyFormatAndSkipsOthers) {
  const std::string dir = test::scratchDir("RawlogReader_Obs");
  RawlogReader r(writeRawlog(dir + "/a.rawlog", false));
  for (int i = 0; i < 3; ++i) {
    auto obs = r.next();
    ASSERT_TRUE(obs);
    EXPECT_NEAR(mrpt::Clock::toDouble(obs->timestamp), i, 1e-6);
    EXPECT_EQ(obs->rangeImage(5, 5), 1234);
  }
  EXPECT_FALSE(r.next());
  EXPECT_EQ(r.otherObservationsSkipped(), 3u);
}

TEST(RawlogReader, ReadsSensoryFrameFormat) {
  const std::string dir = test::scratchDir("RawlogReader_SF");
  RawlogReader r(writeRawlog(dir + "/b.rawlog", true));
  int n = 0;
  while (r.next()) ++n;
  EXPECT_EQ(n, 3);
}

TEST(RawlogReader, TruncatedFileIsAClearError) {
  const std::string dir = test::scratchDir("RawlogReader_Truncated");
  const std::string full = writeRawlog(dir + "/full.rawlog", false);
  const auto size = std::filesystem::file_size(full);
  std::ifstream in(full, std::ios::binary);
  std::string bytes(size, '\0');
  in.read(bytes.data(), size);
  for (double fraction : {0.5, 0.9}) {
    const std::string cut = dir + "/cut.rawlog";
    std::ofstream(cut, std::ios::binary).write(bytes.data(), size * fraction);
    try {
      RawlogReader r(cut);
      while (r.next()) {
      }
      FAIL() << "truncated rawlog read without error";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("cut.rawlog"), std::string::npos) << msg;
      EXPECT_TRUE(msg.find("truncated") != std::string::npos ||
                  msg.find("corrupt") != std::string::npos)
          << msg;
    }
  }
}

TEST(RawlogReader, MissingFileAndNotARawlog) {
  const std::string dir = test::scratchDir("RawlogReader_Missing");
  EXPECT_THROW(RawlogReader(dir + "/nope.rawlog"), std::runtime_error);
  std::ofstream(dir + "/text.rawlog") << "this is not a rawlog at all\n";
  EXPECT_THROW(
      {
        RawlogReader r(dir + "/text.rawlog");
        r.next();
      },
      std::runtime_error);
}

TEST(RawlogReader, ImagesDirectoryNextToRawlog) {
  EXPECT_EQ(RawlogReader::imagesDirectoryFor("/data/seq/x.rawlog"), "/data/seq/x_Images");
}
