// Float descriptors kept as 8-bit codes (keyframes far from the active window): the codes read
// back within half a step, and a frame matched against them finds the matches it finds against
// the floats.

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
