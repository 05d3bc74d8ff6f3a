#include <slamdunk/core/PrefetchingRawlogReader.h>
#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <sys/resource.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>

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
/// A rawlog whose scans keep both images in "<name>_Images", as tum2rawlog and synthetic-rgbd
/// write them (colour PNG, depth as MRPT's external matrix).
std::string writeExternalImagesRawlog(const std::string& dir) {
  const std::string path = dir + "/ext.rawlog";
  const std::string images = RawlogReader::imagesDirectoryFor(path);
  std::filesystem::create_directories(images);
  mrpt::io::CFileGZOutputStream f(path);
  auto a = mrpt::serialization::archiveFrom(f);
  for (int i = 0; i < 3; ++i) {
    auto obs = scanAt(i);
    const std::string rgb = "rgb" + std::to_string(i) + ".png";
    cv::imwrite(images + "/" + rgb, cv::Mat(24, 32, CV_8UC3, cv::Scalar(10, 20, 30 + i)));
    obs->intensityImage.setExternalStorage(rgb);
    obs->rangeImage_convertToExternalStorage("depth" + std::to_string(i) + ".bin", images + "/");
    a << *obs;
  }
  return path;
}

/// Reads every scan of `path` with `read`, removes the images folder, then looks at the
/// colour pixels: they are there only if reading decoded them.
template <class Read>
void expectColourDecodedByTheReader(const std::string& path, Read read) {
  const auto scans = read(path);
  ASSERT_EQ(scans.size(), 3u);
  std::filesystem::remove_all(RawlogReader::imagesDirectoryFor(path));
  for (size_t i = 0; i < scans.size(); ++i) {
    const cv::Mat& colour = scans[i]->intensityImage.asCvMatRef();
    ASSERT_EQ(colour.rows, 24) << "scan " << i;
    EXPECT_EQ(colour.at<cv::Vec3b>(5, 5)[2], 30 + i) << "scan " << i;
    EXPECT_EQ(scans[i]->rangeImage(5, 5), 1234) << "scan " << i;
  }
}

std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> readAll(RawlogReader& r, bool allImages) {
  std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> scans;
  while (auto obs = r.next()) {
    if (allImages)
      loadExternalImages(*obs);
    else
      obs->load();
    scans.push_back(obs);
  }
  return scans;
}
}  // namespace

// MRPT's load() reads an external depth matrix but leaves a lazily stored colour image to its
// first access: a grabber or prefetcher that only called load() left the colour image's file
// read and decoding to the tracking thread. loadExternalImages loads both where it is called.
TEST(RawlogReader, LoadExternalImagesDecodesTheColourImageToo) {
  const std::string dir = test::scratchDir("RawlogReader_ExternalImages");
  {
    // What the bug was: load() alone, images gone, colour pixels not there.
    RawlogReader r(writeExternalImagesRawlog(dir));
    const auto scans = readAll(r, false);
    std::filesystem::remove_all(RawlogReader::imagesDirectoryFor(r.path()));
    EXPECT_ANY_THROW(scans[0]->intensityImage.asCvMatRef());
  }
  expectColourDecodedByTheReader(writeExternalImagesRawlog(dir), [](const std::string& path) {
    RawlogReader r(path);
    return readAll(r, true);
  });
  expectColourDecodedByTheReader(writeExternalImagesRawlog(dir), [](const std::string& path) {
    PrefetchingRawlogReader r(path, 8);
    std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> scans;
    while (auto obs = r.next()) scans.push_back(obs);
    return scans;
  });
}

// Starting at a later frame (slamdunk-rawlog --first-frame) reads past the scans before it
// without loading their images: their files may be missing, and a long recording's skipped
// part costs no decoding.
TEST(RawlogReader, PrefetchingFromALaterScanLoadsNothingBeforeIt) {
  const std::string dir = test::scratchDir("RawlogReader_FirstScan");
  const std::string path = writeExternalImagesRawlog(dir);
  const std::string images = RawlogReader::imagesDirectoryFor(path);
  for (const char* file : {"rgb0.png", "depth0.bin", "rgb1.png", "depth1.bin"})
    ASSERT_TRUE(std::filesystem::remove(images + "/" + file)) << file;
  PrefetchingRawlogReader r(path, PrefetchingRawlogReader::kDefaultDepth, 2);
  const auto scan = r.next();
  ASSERT_TRUE(scan);
  EXPECT_EQ(mrpt::Clock::toDouble(scan->timestamp), 2.0);
  EXPECT_EQ(scan->intensityImage.asCvMatRef().at<cv::Vec3b>(5, 5)[2], 32);
  EXPECT_FALSE(r.next());
  EXPECT_EQ(r.entriesRead(), 3u);

  PrefetchingRawlogReader pastTheEnd(path, 1, 5);
  EXPECT_FALSE(pastTheEnd.next());
}

namespace {
/// Nice value of each thread of this process, by thread id (Linux: getpriority of a thread id
/// gives that thread's own nice value).
std::map<int, int> threadNiceValues() {
  std::map<int, int> nice;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    const int tid = std::stoi(task.path().filename().string());
    nice[tid] = getpriority(PRIO_PROCESS, static_cast<id_t>(tid));
  }
  return nice;
}
}  // namespace

// The consumer waits for the reading thread whenever it is behind: a thread at a lower priority
// (it once read at nice 19) let other work on a busy machine hold the consumer back, up to a
// fuzz input's 10 s timeout in CI.
TEST(RawlogReader, PrefetchingThreadKeepsTheConsumersPriority) {
  const std::string dir = test::scratchDir("RawlogReader_PrefetchPriority");
  const auto before = threadNiceValues();
  const int ours = getpriority(PRIO_PROCESS, 0);  // the process's main thread
  PrefetchingRawlogReader r(writeRawlog(dir + "/a.rawlog", false), 1);
  ASSERT_TRUE(r.next());  // the reading thread is running: it read the first scan
  int readingThreads = 0;
  for (const auto& [tid, nice] : threadNiceValues()) {
    if (before.count(tid)) continue;
    ++readingThreads;
    EXPECT_EQ(nice, ours) << "thread " << tid;
  }
  EXPECT_GE(readingThreads, 1);
  while (r.next()) {
  }
}

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
