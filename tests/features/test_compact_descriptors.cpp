// Float descriptors kept as half floats (keyframes) or 8-bit codes (keyframes far from the
// active window): they read back within half a step, and a frame matched against them finds
// the matches it finds against the floats.

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "TestData.h"
#include "slamdunk/features/CompactDescriptors.h"
#include "slamdunk/features/Surf.h"

namespace {

using namespace slamdunk;

cv::Mat uprightSurf64(const std::string& path) {
  const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(image.empty()) << "cannot read " << path;
  Surf::Params p;
  p.upright = true;
  p.extended = false;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  Surf::create(p)->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
  return descriptors;
}

/// (query, train) pairs whose nearest train row passes the ratio test against the second.
std::set<std::pair<int, int>> ratioMatches(const cv::Mat& queries, const cv::Mat& train) {
  std::set<std::pair<int, int>> out;
  for (int q = 0; q < queries.rows; ++q) {
    double best = 1e9, second = 1e9;
    int bestT = -1;
    for (int t = 0; t < train.rows; ++t) {
      const double d = cv::norm(queries.row(q), train.row(t));
      if (d < best) {
        second = best;
        best = d;
        bestT = t;
      } else if (d < second) {
        second = d;
      }
    }
    if (bestT >= 0 && best < 0.8 * second) out.emplace(q, bestT);
  }
  return out;
}

}  // namespace

TEST(CompactDescriptors, CodesReadBackWithinHalfAStep) {
  cv::Mat floats(3, 4, CV_32F);
  floats.row(0) = cv::Scalar(0.0f);
  floats.at<float>(1, 0) = 0.1234f;
  floats.at<float>(1, 1) = -0.4321f;
  floats.at<float>(1, 2) = 0.7071f;
  floats.at<float>(1, 3) = -0.003f;
  floats.row(2) = cv::Scalar(-1.0f);  // the range's end (a unit vector along an axis)
  const cv::Mat codes = compactDescriptors(floats);
  ASSERT_EQ(codes.type(), CV_8SC1);
  ASSERT_EQ(codes.size(), floats.size());
  const cv::Mat back = matchableDescriptors(codes);
  ASSERT_EQ(back.type(), CV_32FC1);
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(back.at<float>(0, c), 0.0f);
    EXPECT_NEAR(back.at<float>(1, c), floats.at<float>(1, c), 0.5 / kCompactDescriptorScale + 1e-7);
    EXPECT_FLOAT_EQ(back.at<float>(2, c), -1.0f);
  }
  // Float and binary rows are searched as they are; other kinds are refused.
  EXPECT_EQ(matchableDescriptors(floats).data, floats.data);
  const cv::Mat bits(2, 32, CV_8UC1, cv::Scalar(5));
  EXPECT_EQ(matchableDescriptors(bits).data, bits.data);
  EXPECT_THROW(matchableDescriptors(cv::Mat(2, 4, CV_64FC1)), std::invalid_argument);
  EXPECT_THROW(compactDescriptors(bits), std::invalid_argument);
  EXPECT_THROW(compactDescriptors(bits, DescriptorStorage::HalfFloat), std::invalid_argument);

  // Half floats: 11 significant bits, so within 2^-12 of each component's magnitude.
  const cv::Mat halves = compactDescriptors(floats, DescriptorStorage::HalfFloat);
  ASSERT_EQ(halves.type(), CV_16FC1);
  EXPECT_EQ(descriptorStorage(halves.type()), DescriptorStorage::HalfFloat);
  EXPECT_EQ(descriptorStorage(codes.type()), DescriptorStorage::Codes);
  EXPECT_EQ(descriptorStorage(floats.type()), DescriptorStorage::Float);
  const cv::Mat halvesBack = matchableDescriptors(halves);
  ASSERT_EQ(halvesBack.type(), CV_32FC1);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(halvesBack.at<float>(r, c), floats.at<float>(r, c),
                  std::abs(floats.at<float>(r, c)) / 4096 + 1e-7);
  // Half floats make the same codes as the floats they came from, but where rounding twice
  // crosses a code's boundary.
  EXPECT_LE(cv::norm(compactDescriptors(halves), codes, cv::NORM_INF), 1);

  // Row by row (the pool's way) the same floats as the whole matrix.
  for (const cv::Mat& kept : {floats, halves, codes}) {
    const cv::Mat whole = matchableDescriptors(kept);
    cv::Mat rows(kept.rows, kept.cols, CV_32FC1);
    for (int r = 0; r < kept.rows; ++r)
      matchableRow(kept.ptr(r), kept.type(), kept.cols, rows.ptr<float>(r));
    EXPECT_EQ(cv::norm(rows, whole, cv::NORM_INF), 0.0) << "type " << kept.type();
  }
  float out[32];
  EXPECT_THROW(matchableRow(bits.ptr(0), bits.type(), bits.cols, out), std::invalid_argument);
}

TEST(CompactDescriptors, AFrameFindsTheSameMatchesInCodesAsInFloats) {
  SLAMDUNK_REQUIRE_DATA(dir, "tum/fr1_desk_9f/rgb");
  // The first and last of nine frames: a quarter of a second of hand-held motion apart.
  const cv::Mat keyframe = uprightSurf64(dir + "/1305031453.359684.png");
  const cv::Mat frame = uprightSurf64(dir + "/1305031453.627706.png");
  ASSERT_GT(keyframe.rows, 200);
  ASSERT_GT(frame.rows, 200);

  // Every code reads back within half a step of its float.
  const cv::Mat back = matchableDescriptors(compactDescriptors(keyframe));
  EXPECT_LE(cv::norm(back, keyframe, cv::NORM_INF), 0.5 / kCompactDescriptorScale + 1e-7);

  const auto fromFloats = ratioMatches(frame, keyframe);
  const auto fromCodes = ratioMatches(frame, back);
  size_t both = 0;
  for (const auto& m : fromFloats) both += fromCodes.count(m);
  std::printf("[ matches ] %zu from floats, %zu from codes, %zu in both (%d x %d descriptors)\n",
              fromFloats.size(), fromCodes.size(), both, frame.rows, keyframe.rows);
  ASSERT_GT(fromFloats.size(), 100u);
  EXPECT_GE(both, 0.97 * fromFloats.size());
  EXPECT_GE(both, 0.97 * fromCodes.size());
}

TEST(CompactDescriptors, AFrameFindsTheSameMatchesInHalfFloatsAsInFloats) {
  SLAMDUNK_REQUIRE_DATA(dir, "tum/fr1_desk_9f/rgb");
  const cv::Mat keyframe = uprightSurf64(dir + "/1305031453.359684.png");
  const cv::Mat frame = uprightSurf64(dir + "/1305031453.627706.png");
  ASSERT_GT(keyframe.rows, 200);
  const cv::Mat back =
      matchableDescriptors(compactDescriptors(keyframe, DescriptorStorage::HalfFloat));
  EXPECT_LE(cv::norm(back, keyframe, cv::NORM_INF), 1.0 / 4096);  // components below 1

  const auto fromFloats = ratioMatches(frame, keyframe);
  const auto fromHalves = ratioMatches(frame, back);
  size_t both = 0;
  for (const auto& m : fromFloats) both += fromHalves.count(m);
  std::printf("[ matches ] %zu from floats, %zu from half floats, %zu in both\n", fromFloats.size(),
              fromHalves.size(), both);
  ASSERT_GT(fromFloats.size(), 100u);
  EXPECT_GE(both, 0.99 * fromFloats.size());
  EXPECT_GE(both, 0.99 * fromHalves.size());
}
