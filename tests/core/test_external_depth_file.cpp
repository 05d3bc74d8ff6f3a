// loadExternalDepthFile(): the depth MRPT wrote beside a rawlog comes back value for value, as
// MRPT's own load() reads it; what it cannot read (a text file, a damaged file, a depth already
// loaded) it leaves untouched for load(), which reads it or reports the problem.

#include <slamdunk/core/ExternalDepthFile.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/img/CImage.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <filesystem>
#include <fstream>

using mrpt::obs::CObservation3DRangeScan;
using namespace slamdunk;

namespace {
/// A depth image whose values differ from pixel to pixel (and use the high byte).
mrpt::math::CMatrix_u16 varyingDepth() {
  mrpt::math::CMatrix_u16 depth(48, 64);
  for (int r = 0; r < depth.rows(); ++r)
    for (int c = 0; c < depth.cols(); ++c) depth(r, c) = static_cast<uint16_t>((r * 64 + c) * 37);
  return depth;
}

/// An observation whose depth was moved to `file` in `dir`, as tum2rawlog stores it.
CObservation3DRangeScan externallyStored(const std::string& dir, const std::string& file) {
  CObservation3DRangeScan obs;
  obs.hasRangeImage = true;
  obs.rangeImage = varyingDepth();
  obs.rangeImage_convertToExternalStorage(file, dir + "/");
  return obs;
}

/// MRPT resolves an external file's name against the images folder it is told about.
struct ImagesFolder {
  explicit ImagesFolder(const std::string& dir) : saved(mrpt::img::CImage::getImagesPathBase()) {
    mrpt::img::CImage::setImagesPathBase(dir);
  }
  ~ImagesFolder() { mrpt::img::CImage::setImagesPathBase(saved); }
  std::string saved;
};
}  // namespace

TEST(ExternalDepthFile, ReadsWhatMrptWroteAsMrptReadsIt) {
  const std::string dir = test::scratchDir("ExternalDepthFile_Reads");
  ImagesFolder folder(dir);
  const CObservation3DRangeScan stored = externallyStored(dir, "depth.bin");
  ASSERT_EQ(stored.rangeImage.rows(), 0) << "MRPT keeps an external depth unloaded";

  CObservation3DRangeScan ours = stored, mrpts = stored;
  ASSERT_TRUE(loadExternalDepthFile(ours));
  mrpts.load();
  EXPECT_EQ(ours.rangeImage.asEigen(), varyingDepth().asEigen());
  EXPECT_EQ(ours.rangeImage.asEigen(), mrpts.rangeImage.asEigen());
  EXPECT_FALSE(loadExternalDepthFile(ours)) << "a depth already loaded is left as it is";
}

TEST(ExternalDepthFile, LeavesWhatItCannotReadToMrpt) {
  const std::string dir = test::scratchDir("ExternalDepthFile_Leaves");
  ImagesFolder folder(dir);

  // A damaged file: MRPT's load() reports it.
  CObservation3DRangeScan damaged = externallyStored(dir, "damaged.bin");
  const auto path = std::filesystem::path(dir) / "damaged.bin";
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
  EXPECT_FALSE(loadExternalDepthFile(damaged));
  EXPECT_EQ(damaged.rangeImage.rows(), 0);

  // A missing file.
  CObservation3DRangeScan missing = externallyStored(dir, "missing.bin");
  std::filesystem::remove(std::filesystem::path(dir) / "missing.bin");
  EXPECT_FALSE(loadExternalDepthFile(missing));
  EXPECT_EQ(missing.rangeImage.rows(), 0);

  // Text, which MRPT writes when told to: its load() reads it.
  CObservation3DRangeScan::EXTERNALS_AS_TEXT(true);
  CObservation3DRangeScan text = externallyStored(dir, "text.bin");
  CObservation3DRangeScan::EXTERNALS_AS_TEXT(false);
  EXPECT_FALSE(loadExternalDepthFile(text));
  text.load();
  EXPECT_EQ(text.rangeImage.asEigen(), varyingDepth().asEigen());

  // An observation whose depth is its own.
  CObservation3DRangeScan inMemory;
  inMemory.hasRangeImage = true;
  inMemory.rangeImage = varyingDepth();
  EXPECT_FALSE(loadExternalDepthFile(inMemory));
}
