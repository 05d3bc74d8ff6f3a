// Tests of slamdunk::Surf: output contract, repeatability and matching under known image
// transformations of real frames, determinism and edge cases.

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "TestData.h"
#include "slamdunk/features/FeatureExtractor.h"
#include "slamdunk/features/Surf.h"

#include <slamdunk/core/Statistics.h>

namespace {

using slamdunk::Surf;
using slamdunk::upperMedian;

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};

Features run(const cv::Mat& image, const Surf::Params& params = Surf::Params()) {
  Features f;
  Surf::create(params)->detectAndCompute(image, cv::noArray(), f.keypoints, f.descriptors);
  return f;
}

Surf::Params makeParams(bool upright, bool extended, double threshold = 500) {
  Surf::Params p;
  p.upright = upright;
  p.extended = extended;
  p.hessianThreshold = threshold;
  return p;
}

cv::Point2f apply(const cv::Matx23d& m, const cv::Point2f& p) {
  return cv::Point2f(static_cast<float>(m(0, 0) * p.x + m(0, 1) * p.y + m(0, 2)),
                     static_cast<float>(m(1, 0) * p.x + m(1, 1) * p.y + m(1, 2)));
}

/// Agreement between features of an image A and of its transformation B (b = m * a).
struct Comparison {
  int comparable = 0;  ///< keypoints of A that land inside B, away from its border
  int repeated = 0;    ///< ... with a keypoint of B within kMaxPixels and a consistent scale
  int nnCorrect = 0;   ///< ... whose nearest descriptor in B is at the right place
  int sameLaplacian = 0;
  int angleConsistent = 0;  ///< ... whose angle turned by the rotation of m, within 15 degrees
  std::vector<double> matchedDistances;  ///< descriptor distances of repeated pairs
  std::vector<double> randomDistances;   ///< descriptor distances of random pairs

  double repeatability() const { return comparable ? double(repeated) / comparable : 0; }
  double nnPrecision() const { return repeated ? double(nnCorrect) / repeated : 0; }
};

constexpr float kMaxPixels = 3.f;
constexpr float kBorder = 20.f;

int nearest(const std::vector<cv::KeyPoint>& kps, const cv::Point2f& p, float& dist) {
  int best = -1;
  dist = 1e9f;
  for (int j = 0; j < static_cast<int>(kps.size()); ++j) {
    const float d = static_cast<float>(cv::norm(kps[j].pt - p));
    if (d < dist) {
      dist = d;
      best = j;
    }
  }
  return best;
}

int nearestDescriptor(const cv::Mat& query, const cv::Mat& all) {
  int best = -1;
  double bestDist = 1e9;
  for (int j = 0; j < all.rows; ++j) {
    const double d = cv::norm(query, all.row(j), cv::NORM_L2);
    if (d < bestDist) {
      bestDist = d;
      best = j;
    }
  }
  return best;
}

Comparison compare(const Features& a, const Features& b, const cv::Matx23d& m, double scale,
                   const cv::Size& sizeB) {
  Comparison c;
  std::mt19937 rng(42);
  for (int i = 0; i < static_cast<int>(a.keypoints.size()); ++i) {
    const cv::Point2f p = apply(m, a.keypoints[i].pt);
    if (p.x < kBorder || p.y < kBorder || p.x > sizeB.width - kBorder ||
        p.y > sizeB.height - kBorder)
      continue;
    ++c.comparable;
    float dist;
    const int j = nearest(b.keypoints, p, dist);
    if (j < 0 || dist > kMaxPixels) continue;
    const double sizeRatio = b.keypoints[j].size / (a.keypoints[i].size * scale);
    if (std::abs(std::log(sizeRatio)) > std::log(1.5)) continue;
    ++c.repeated;
    if (a.keypoints[i].class_id == b.keypoints[j].class_id) ++c.sameLaplacian;
    // KeyPoint angles are clockwise on screen (y down); m rotates by atan2(m10, m00) that way.
    const double turn = std::atan2(m(1, 0), m(0, 0)) * 180.0 / CV_PI;
    const double error = std::remainder(b.keypoints[j].angle - a.keypoints[i].angle - turn, 360.0);
    if (a.keypoints[i].angle >= 0 && std::abs(error) < 15.0) ++c.angleConsistent;
    const cv::Mat da = a.descriptors.row(i);
    c.matchedDistances.push_back(cv::norm(da, b.descriptors.row(j), cv::NORM_L2));
    const int other = std::uniform_int_distribution<int>(0, b.descriptors.rows - 1)(rng);
    c.randomDistances.push_back(cv::norm(da, b.descriptors.row(other), cv::NORM_L2));
    const int nn = nearestDescriptor(da, b.descriptors);
    if (cv::norm(b.keypoints[nn].pt - p) <= kMaxPixels) ++c.nnCorrect;
  }
  return c;
}

void print(const std::string& what, const Comparison& c) {
  std::printf(
      "[ %s ] comparable %d, repeatability %.3f, NN precision %.3f, same Laplacian %d/%d, "
      "consistent angle %d/%d\n",
      what.c_str(), c.comparable, c.repeatability(), c.nnPrecision(), c.sameLaplacian, c.repeated,
      c.angleConsistent, c.repeated);
}

cv::Mat loadGray(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(image.empty()) << "cannot read " << path;
  return image;
}

/// Frame 0 of the 7-Scenes sequence (VGA); the tests below skip without the data.
#define LOAD_7SCENES_FRAME(image)                             \
  SLAMDUNK_REQUIRE_DATA(dir_, "7scenes/seq-1000f");           \
  const cv::Mat image = loadGray(dir_ + "/rgb/0.000000.jpg"); \
  ASSERT_FALSE(image.empty())

/// Synthetic image: bright disc (radius r) on a dark background, slightly blurred.
cv::Mat discImage(int r, cv::Point centre, cv::Size size = cv::Size(160, 160)) {
  cv::Mat image(size, CV_8UC1, cv::Scalar(40));
  cv::circle(image, centre, r, cv::Scalar(210), cv::FILLED, cv::LINE_AA);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  return image;
}

// ---------------------------------------------------------------------------------------------
// Contract of the output

TEST(Surf, DescribesItselfAsFeature2D) {
  Surf::Params p;
  EXPECT_EQ(Surf::create(p)->descriptorSize(), 64);
  p.extended = true;
  const cv::Ptr<cv::Feature2D> f = Surf::create(p);
  EXPECT_EQ(f->descriptorSize(), 128);
  EXPECT_EQ(f->descriptorType(), CV_32F);
  EXPECT_EQ(f->defaultNorm(), cv::NORM_L2);
}

TEST(Surf, FindsSyntheticBlobAtItsCentreAndScale) {
  const cv::Point centre(83, 77);
  const Features f = run(discImage(10, centre), makeParams(false, false, 100));
  ASSERT_FALSE(f.keypoints.empty());
  float dist;
  const int j = nearest(f.keypoints, cv::Point2f(centre), dist);
  EXPECT_LT(dist, 1.0f);
  // A disc of radius r responds most at sigma ~ r / sqrt(2); size = 9 / 1.2 * sigma ~ 53.
  EXPECT_GT(f.keypoints[j].size, 35.f);
  EXPECT_LT(f.keypoints[j].size, 75.f);
  EXPECT_EQ(f.keypoints[j].class_id, -1) << "bright blob: negative Laplacian";
  // The inverted image has the same keypoint with the opposite Laplacian sign.
  cv::Mat inverted = 255 - discImage(10, centre);
  const Features g = run(inverted, makeParams(false, false, 100));
  const int k = nearest(g.keypoints, cv::Point2f(centre), dist);
  ASSERT_GE(k, 0);
  EXPECT_LT(dist, 1.0f);
  EXPECT_EQ(g.keypoints[k].class_id, +1);
}

TEST(Surf, RealFrameGivesSortedKeypointsAndUnitDescriptors) {
  LOAD_7SCENES_FRAME(image);
  for (bool extended : {false, true}) {
    const Features f = run(image, makeParams(false, extended));
    const int n = static_cast<int>(f.keypoints.size());
    std::printf("[ frame 0 ] extended=%d: %d keypoints\n", extended, n);
    EXPECT_GT(n, 100);
    EXPECT_LT(n, 5000);
    ASSERT_EQ(f.descriptors.rows, n);
    EXPECT_EQ(f.descriptors.cols, extended ? 128 : 64);
    EXPECT_EQ(f.descriptors.type(), CV_32F);
    for (int i = 0; i < n; ++i) {
      const cv::KeyPoint& kp = f.keypoints[i];
      EXPECT_NEAR(cv::norm(f.descriptors.row(i)), 1.0, 1e-4);
      EXPECT_TRUE(kp.class_id == 1 || kp.class_id == -1);
      EXPECT_GE(kp.angle, 0.f);
      EXPECT_LT(kp.angle, 360.f);
      EXPECT_GE(kp.size, 9.f);
      EXPECT_GT(kp.response, 500.f);
      EXPECT_TRUE(kp.pt.x >= 0 && kp.pt.y >= 0 && kp.pt.x < image.cols && kp.pt.y < image.rows);
      if (i > 0) EXPECT_GE(f.keypoints[i - 1].response, kp.response) << "not sorted at " << i;
    }
    // Several octaves contribute.
    const int maxOctave =
        std::max_element(f.keypoints.begin(), f.keypoints.end(), [](auto& a, auto& b) {
          return a.octave < b.octave;
        })->octave;
    EXPECT_GE(maxOctave, 2);
  }
}

TEST(Surf, LowerThresholdGivesMoreKeypointsAndMaxKeypointsCaps) {
  LOAD_7SCENES_FRAME(image);
  const Features strict = run(image, makeParams(true, false, 1000));
  const Features loose = run(image, makeParams(true, false, 100));
  std::printf("[ counts ] threshold 1000: %zu, 100: %zu\n", strict.keypoints.size(),
              loose.keypoints.size());
  EXPECT_GT(loose.keypoints.size(), strict.keypoints.size() * 3 / 2);
  Surf::Params lenient = makeParams(true, false, 1000);
  lenient.maxInterpolationOffset = 1.0;
  EXPECT_GT(run(image, lenient).keypoints.size(), strict.keypoints.size());
  Surf::Params capped = makeParams(true, false, 100);
  capped.maxKeypoints = 150;
  const Features best = run(image, capped);
  ASSERT_EQ(best.keypoints.size(), 150u);
  for (int i = 0; i < 150; ++i) {
    EXPECT_EQ(best.keypoints[i].pt, loose.keypoints[i].pt);
    EXPECT_EQ(cv::norm(best.descriptors.row(i), loose.descriptors.row(i), cv::NORM_INF), 0.0);
  }
}

// ---------------------------------------------------------------------------------------------
// Invariance, measured with known transformations of a real frame

// A keypoint of image A is repeated if a keypoint of the transformed image B lies within 3 px of
// its mapped position with a size within a factor 1.5; its descriptor matches if the nearest
// descriptor of B belongs to a keypoint within 3 px. Measured on 7-Scenes frame 0, threshold
// 500, paper settings (maxInterpolationOffset 0.5):
//   rotation 30 deg: repeatability 0.47, NN precision 0.77, angle within 15 deg 0.87
//   rotation 90 deg (warpAffine): 0.87, 0.98, 0.99
// The box filters are not isotropic, so non-multiple-of-90 rotations lose maxima (SIFT scores
// 0.73 at 30 deg with the same 3 px criterion); the bounds leave a margin for other compilers.
TEST(Surf, RepeatableAndMatchableUnderRotation) {
  LOAD_7SCENES_FRAME(image);
  const cv::Point2f centre((image.cols - 1) * 0.5f, (image.rows - 1) * 0.5f);
  const Features a = run(image);
  for (double degrees : {30.0, 90.0}) {
    const cv::Matx23d m = cv::getRotationMatrix2D(centre, degrees, 1.0);
    cv::Mat rotated;
    cv::warpAffine(image, rotated, m, image.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    const Comparison c = compare(a, run(rotated), m, 1.0, rotated.size());
    print("rotation " + std::to_string(int(degrees)), c);
    EXPECT_GT(c.comparable, 100);
    EXPECT_GT(c.repeatability(), degrees == 90.0 ? 0.80 : 0.40);
    EXPECT_GT(c.nnPrecision(), degrees == 90.0 ? 0.90 : 0.65);
    EXPECT_GT(c.sameLaplacian, 0.97 * c.repeated);
    EXPECT_GT(c.angleConsistent, 0.80 * c.repeated);
  }
}

// An exact quarter turn maps the box filters onto themselves: detection must be identical
// provided the sampling grids of all octaves (steps 1, 2, 4, 8) map onto each other, i.e. the
// image width and height are 1 + a multiple of 8. Measured: 1.00 and 1.00.
TEST(Surf, ExactQuarterTurnIsAlmostPerfect) {
  LOAD_7SCENES_FRAME(full);
  const cv::Mat image =
      full(cv::Rect(0, 0, 1 + (full.cols - 1) / 8 * 8, 1 + (full.rows - 1) / 8 * 8));
  cv::Mat rotated;
  cv::rotate(image, rotated, cv::ROTATE_90_CLOCKWISE);
  // Pixel (x, y) moves to (rows - 1 - y, x).
  const cv::Matx23d m(0, -1, image.rows - 1, 1, 0, 0);
  const Comparison c = compare(run(image), run(rotated), m, 1.0, rotated.size());
  print("quarter turn", c);
  EXPECT_GT(c.repeatability(), 0.97);
  EXPECT_GT(c.nnPrecision(), 0.97);
}

// Windows turned by nothing sample where upright ones do and rotate their responses by the
// identity: the same descriptors, bit for bit, for keypoints inside the image (turned windows
// read the table unclamped there) and near its border (clamped).
TEST(Surf, WindowsTurnedByNothingAreDescribedAsUpright) {
  LOAD_7SCENES_FRAME(image);
  Surf::Params p;
  p.upright = true;
  const cv::Ptr<Surf> surf = Surf::create(p);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat upright;
  surf->detectAndCompute(image, cv::noArray(), keypoints, upright);
  std::vector<cv::KeyPoint> turnedKeypoints = keypoints;
  cv::Mat turned;
  surf->computeTurned(image, turnedKeypoints, turned, 0.f);
  ASSERT_EQ(turned.rows, upright.rows);
  EXPECT_EQ(cv::norm(turned, upright, cv::NORM_INF), 0.0);
  const auto nearBorder = [&](const cv::KeyPoint& kp) {
    const float reach = 15.f * kp.size * 1.2f / 9.f;  // 10 s and the wavelet, past the corner
    return kp.pt.x < reach || kp.pt.y < reach || kp.pt.x > image.cols - reach ||
           kp.pt.y > image.rows - reach;
  };
  const auto border = std::count_if(keypoints.begin(), keypoints.end(), nearBorder);
  EXPECT_GT(border, 10);
  EXPECT_GT(static_cast<long>(keypoints.size()) - border, 100);
}

// Measured: scale 0.7: repeatability 0.48, NN precision 0.83; scale 1.5: 0.59, 0.89.
TEST(Surf, RepeatableAndMatchableUnderScale) {
  LOAD_7SCENES_FRAME(image);
  const Features a = run(image);
  for (double scale : {0.7, 1.5}) {
    cv::Mat resized;
    cv::resize(image, resized, cv::Size(), scale, scale,
               scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
    // cv::resize aligns pixel areas: x' = (x + 0.5) * scale - 0.5.
    const double shift = 0.5 * scale - 0.5;
    const cv::Matx23d m(scale, 0, shift, 0, scale, shift);
    const Comparison c = compare(a, run(resized), m, scale, resized.size());
    print("scale " + std::to_string(scale), c);
    EXPECT_GT(c.comparable, 100);
    EXPECT_GT(c.repeatability(), 0.40);
    EXPECT_GT(c.nnPrecision(), 0.70);
  }
}

TEST(Surf, CorrespondingDescriptorsAreMuchCloserThanRandomPairs) {
  LOAD_7SCENES_FRAME(image);
  const cv::Point2f centre((image.cols - 1) * 0.5f, (image.rows - 1) * 0.5f);
  const cv::Matx23d m = cv::getRotationMatrix2D(centre, 20.0, 0.9);
  cv::Mat warped;
  cv::warpAffine(image, warped, m, image.size());
  for (bool extended : {false, true}) {
    const Comparison c = compare(run(image, makeParams(false, extended)),
                                 run(warped, makeParams(false, extended)), m, 0.9, warped.size());
    const double matched = upperMedian(c.matchedDistances);
    const double random = upperMedian(c.randomDistances);
    // Measured: 64 values 0.17 vs 0.86; 128 values 0.39 vs 1.04.
    std::printf("[ distances ] extended=%d: median matched %.3f, random %.3f\n", extended, matched,
                random);
    ASSERT_GT(c.repeated, 50);
    EXPECT_LT(matched, 0.5 * random);
  }
}

TEST(Surf, UprightMatchesUnrotatedImagesButNotRotatedOnes) {
  LOAD_7SCENES_FRAME(image);
  const Features a = run(image, makeParams(true, false));
  for (const cv::KeyPoint& kp : a.keypoints) ASSERT_EQ(kp.angle, -1.f);

  cv::Mat resized;
  cv::resize(image, resized, cv::Size(), 0.8, 0.8, cv::INTER_AREA);
  const cv::Matx23d m(0.8, 0, -0.1, 0, 0.8, -0.1);
  const Comparison scaled =
      compare(a, run(resized, makeParams(true, false)), m, 0.8, resized.size());
  print("upright, scale 0.8", scaled);  // measured 0.53, 0.90
  EXPECT_GT(scaled.repeatability(), 0.45);
  EXPECT_GT(scaled.nnPrecision(), 0.80);

  // At 45 degrees the upright descriptor must lose most matches the rotating one keeps: this
  // proves the orientation assignment does its job (measured NN precision 0.03 vs 0.77).
  const cv::Point2f centre((image.cols - 1) * 0.5f, (image.rows - 1) * 0.5f);
  const cv::Matx23d r = cv::getRotationMatrix2D(centre, 45.0, 1.0);
  cv::Mat rotated;
  cv::warpAffine(image, rotated, r, image.size());
  const Comparison upright =
      compare(a, run(rotated, makeParams(true, false)), r, 1.0, rotated.size());
  const Comparison oriented = compare(run(image), run(rotated), r, 1.0, rotated.size());
  print("upright, rotation 45", upright);
  print("oriented, rotation 45", oriented);
  EXPECT_LT(upright.nnPrecision(), 0.5 * oriented.nnPrecision());
}

TEST(Surf, MatchesAcrossConsecutiveTumFrames) {
  SLAMDUNK_REQUIRE_DATA(dir, "tum/fr1_desk_9f/rgb");
  const cv::Mat a = loadGray(dir + "/1305031453.359684.png");
  const cv::Mat b = loadGray(dir + "/1305031453.391690.png");
  ASSERT_FALSE(a.empty() || b.empty());
  const Features fa = run(a), fb = run(b);
  ASSERT_GT(fa.keypoints.size(), 50u);
  ASSERT_GT(fb.keypoints.size(), 50u);
  // Mutual nearest neighbours that pass Lowe's ratio test.
  std::vector<cv::Point2f> pa, pb;
  for (int i = 0; i < fa.descriptors.rows; ++i) {
    double best = 1e9, second = 1e9;
    int bestJ = -1;
    for (int j = 0; j < fb.descriptors.rows; ++j) {
      const double d = cv::norm(fa.descriptors.row(i), fb.descriptors.row(j));
      if (d < best) {
        second = best;
        best = d;
        bestJ = j;
      } else if (d < second) {
        second = d;
      }
    }
    if (bestJ >= 0 && best < 0.7 * second &&
        nearestDescriptor(fb.descriptors.row(bestJ), fa.descriptors) == i) {
      pa.push_back(fa.keypoints[i].pt);
      pb.push_back(fb.keypoints[bestJ].pt);
    }
  }
  std::printf("[ tum ] %zu / %zu keypoints matched\n", pa.size(), fa.keypoints.size());
  ASSERT_GT(pa.size(), 40u);
  // Frames 32 ms apart move little, so nearly all correct matches have a displacement close to
  // the median one; wrong matches land anywhere.
  std::vector<double> dx, dy;
  for (size_t i = 0; i < pa.size(); ++i) {
    dx.push_back(pb[i].x - pa[i].x);
    dy.push_back(pb[i].y - pa[i].y);
  }
  const double mx = upperMedian(dx), my = upperMedian(dy);
  size_t consistent = 0;
  for (size_t i = 0; i < pa.size(); ++i)
    if (std::hypot(dx[i] - mx, dy[i] - my) < 15.0) ++consistent;
  EXPECT_GT(consistent, 0.85 * pa.size());
}

// ---------------------------------------------------------------------------------------------
// Determinism and API behaviour

TEST(Surf, DeterministicAcrossRunsAndThreadCounts) {
  LOAD_7SCENES_FRAME(image);
  const int threads = cv::getNumThreads();
  for (bool upright : {false, true}) {
    const Features first = run(image, makeParams(upright, true));
    const Features second = run(image, makeParams(upright, true));
    cv::setNumThreads(1);
    const Features single = run(image, makeParams(upright, true));
    cv::setNumThreads(threads);
    for (const Features* other : {&second, &single}) {
      ASSERT_EQ(first.keypoints.size(), other->keypoints.size());
      for (size_t i = 0; i < first.keypoints.size(); ++i) {
        const cv::KeyPoint& p = first.keypoints[i];
        const cv::KeyPoint& q = other->keypoints[i];
        ASSERT_TRUE(p.pt == q.pt && p.size == q.size && p.angle == q.angle &&
                    p.response == q.response && p.octave == q.octave && p.class_id == q.class_id)
            << "keypoint " << i << " differs";
      }
      EXPECT_EQ(cv::norm(first.descriptors, other->descriptors, cv::NORM_INF), 0.0);
    }
  }
}

// A rolled camera's view described with its windows turned back by the roll matches the level
// view's upright descriptors as well as orientation assignment does, where upright ones fail.
TEST(Surf, TurnedWindowsMatchARolledViewsUprightDescriptors) {
  LOAD_7SCENES_FRAME(image);
  const Features level = run(image, makeParams(true, false));
  const cv::Point2f centre((image.cols - 1) * 0.5f, (image.rows - 1) * 0.5f);
  const cv::Matx23d r = cv::getRotationMatrix2D(centre, 45.0, 1.0);
  cv::Mat rolled;
  cv::warpAffine(image, rolled, r, image.size());
  const cv::Ptr<Surf> surf = Surf::create(makeParams(true, false));
  Features turned;
  surf->detect(rolled, turned.keypoints);
  // getRotationMatrix2D turns counter-clockwise on screen: -45 degrees in KeyPoint angles.
  surf->computeTurned(rolled, turned.keypoints, turned.descriptors, -45.f);
  for (const cv::KeyPoint& kp : turned.keypoints) ASSERT_EQ(kp.angle, 315.f);

  const Comparison c = compare(level, turned, r, 1.0, rolled.size());
  const Comparison upright =
      compare(level, run(rolled, makeParams(true, false)), r, 1.0, rolled.size());
  const Comparison oriented = compare(run(image), run(rolled), r, 1.0, rolled.size());
  print("upright against turned by the roll, rotation 45", c);  // measured NN precision 0.90
  EXPECT_GT(c.nnPrecision(), oriented.nnPrecision());
  EXPECT_GT(c.nnPrecision(), 2 * upright.nnPrecision());

  // Turned by nothing, the windows are the upright ones.
  std::vector<cv::KeyPoint> again = level.keypoints;
  cv::Mat notTurned;
  surf->computeTurned(image, again, notTurned, 0.f);
  EXPECT_EQ(cv::norm(notTurned, level.descriptors, cv::NORM_INF), 0.0);
}

TEST(Surf, ComputeOnDetectedKeypointsEqualsDetectAndCompute) {
  LOAD_7SCENES_FRAME(image);
  const cv::Ptr<Surf> surf = Surf::create(makeParams(false, false));
  std::vector<cv::KeyPoint> detected;
  surf->detect(image, detected);
  cv::Mat described;
  surf->compute(image, detected, described);
  const Features both = run(image, makeParams(false, false));
  ASSERT_EQ(detected.size(), both.keypoints.size());
  EXPECT_EQ(cv::norm(described, both.descriptors, cv::NORM_INF), 0.0);

  // Keypoints that cannot be described are removed by compute().
  std::vector<cv::KeyPoint> odd = {cv::KeyPoint(100, 100, 20), cv::KeyPoint(-5, 10, 20),
                                   cv::KeyPoint(50, 50, 0)};
  surf->compute(image, odd, described);
  ASSERT_EQ(odd.size(), 1u);
  EXPECT_EQ(described.rows, 1);
  EXPECT_NEAR(cv::norm(described), 1.0, 1e-4);
}

TEST(Surf, MaskRestrictsKeypoints) {
  LOAD_7SCENES_FRAME(image);
  cv::Mat mask = cv::Mat::zeros(image.size(), CV_8UC1);
  mask(cv::Rect(0, 0, image.cols / 2, image.rows)).setTo(255);
  std::vector<cv::KeyPoint> kps;
  Surf::create()->detect(image, kps, mask);
  ASSERT_GT(kps.size(), 30u);
  for (const cv::KeyPoint& kp : kps) EXPECT_LT(kp.pt.x, image.cols / 2.f);
  EXPECT_THROW(Surf::create()->detect(image, kps, cv::Mat::ones(10, 10, CV_8UC1)), cv::Exception);
}

TEST(Surf, ColourAnd16BitInputGiveTheSameResultAsGrey) {
  LOAD_7SCENES_FRAME(grey);
  const cv::Mat colour = cv::imread(dir_ + "/rgb/0.000000.jpg", cv::IMREAD_COLOR);
  ASSERT_EQ(colour.type(), CV_8UC3);
  cv::Mat greyOfColour, wide;
  cv::cvtColor(colour, greyOfColour, cv::COLOR_BGR2GRAY);
  greyOfColour.convertTo(wide, CV_16U, 257.0);
  const Features reference = run(greyOfColour);
  for (const cv::Mat input : {colour, wide}) {
    const Features f = run(input);
    ASSERT_EQ(f.keypoints.size(), reference.keypoints.size());
    EXPECT_EQ(cv::norm(f.descriptors, reference.descriptors, cv::NORM_INF), 0.0);
  }
}

TEST(Surf, EdgeCasesDoNotCrash) {
  const cv::Ptr<Surf> surf = Surf::create();
  std::vector<cv::KeyPoint> kps = {cv::KeyPoint(1, 1, 10)};
  cv::Mat desc = cv::Mat::ones(3, 3, CV_32F);
  surf->detectAndCompute(cv::Mat(), cv::noArray(), kps, desc);
  EXPECT_TRUE(kps.empty());
  EXPECT_TRUE(desc.empty());

  for (int side : {1, 5, 20, 30}) {
    cv::Mat tiny(side, side, CV_8UC1);
    cv::randu(tiny, 0, 255);
    surf->detectAndCompute(tiny, cv::noArray(), kps, desc);
    EXPECT_EQ(desc.rows, static_cast<int>(kps.size()));
    // Describing a large keypoint on a tiny image stays finite.
    std::vector<cv::KeyPoint> given = {cv::KeyPoint((side - 1) * 0.5f, (side - 1) * 0.5f, 60)};
    surf->compute(tiny, given, desc);
    ASSERT_EQ(desc.rows, 1);
    EXPECT_TRUE(cv::checkRange(desc));
  }
  // A thin strip: octaves that do not fit are skipped.
  cv::Mat strip(12, 640, CV_8UC1);
  cv::randu(strip, 0, 255);
  EXPECT_NO_THROW(surf->detectAndCompute(strip, cv::noArray(), kps, desc));
  EXPECT_TRUE(kps.empty());
}

TEST(Surf, OddImageSizesGiveValidOutput) {
  // Sizes around the filter sizes and sampling steps, where off-by-one errors would show.
  cv::RNG rng(7);
  for (const cv::Size size :
       {cv::Size(27, 27), cv::Size(28, 53), cv::Size(52, 29), cv::Size(101, 37), cv::Size(203, 99),
        cv::Size(99, 203), cv::Size(257, 131)}) {
    cv::Mat image(size, CV_8UC1);
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
    for (bool upright : {false, true}) {
      const Features f = run(image, makeParams(upright, false, 10));
      ASSERT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
      if (std::min(size.width, size.height) >= 99) EXPECT_GT(f.keypoints.size(), 5u) << size;
      for (const cv::KeyPoint& kp : f.keypoints) {
        EXPECT_TRUE(kp.pt.x >= 0 && kp.pt.y >= 0 && kp.pt.x <= size.width - 1 &&
                    kp.pt.y <= size.height - 1)
            << size;
      }
      if (!f.descriptors.empty()) EXPECT_TRUE(cv::checkRange(f.descriptors));
    }
  }
}

TEST(Surf, RejectsUnsupportedInputClearly) {
  const cv::Ptr<Surf> surf = Surf::create();
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  EXPECT_THROW(surf->detectAndCompute(cv::Mat::zeros(64, 64, CV_32F), cv::noArray(), kps, desc),
               cv::Exception);
  EXPECT_THROW(surf->detectAndCompute(cv::Mat::zeros(64, 64, CV_8UC2), cv::noArray(), kps, desc),
               cv::Exception);
  EXPECT_THROW(surf->detectAndCompute(cv::Mat::zeros(64, 64, CV_16S), cv::noArray(), kps, desc),
               cv::Exception);
  Surf::Params bad;
  bad.nOctaves = 0;
  EXPECT_THROW(Surf::create(bad), cv::Exception);
}

}  // namespace

// A rolled frame described with its windows turned at once (the tracker extracting on its own
// thread) gets the descriptors it gets described upright and turned after (features extracted
// ahead): the two ways of tracking a frame stay bit for bit the same.
TEST(FeatureExtractor, DescribesAFrameTurnedAtOnceAsTurnedAfterwards) {
  LOAD_7SCENES_FRAME(image);
  const slamdunk::RgbdFrame frame(0.0, image, cv::Mat(image.size(), CV_32F, cv::Scalar(2.0f)),
                                  slamdunk::CameraIntrinsics{});
  const slamdunk::FeatureExtractor extractor{slamdunk::FeatureOptions{}};
  const double turn = -17.5;

  const slamdunk::FeatureSet upright = extractor.extract(frame);
  slamdunk::FeatureSet turnedAfter = upright;
  ASSERT_TRUE(extractor.describeTurned(frame, turnedAfter, turn));
  const slamdunk::FeatureSet atOnce = extractor.extract(frame, turn);

  ASSERT_GT(upright.size(), 100u);
  ASSERT_EQ(atOnce.size(), upright.size());
  EXPECT_EQ(cv::norm(atOnce.descriptors, turnedAfter.descriptors, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(atOnce.descriptors, upright.descriptors, cv::NORM_INF), 0.1);
  EXPECT_EQ(atOnce.points, upright.points);
  EXPECT_TRUE(extractor.describedWith(atOnce, turn));
  EXPECT_FALSE(extractor.describedWith(atOnce, turn + 0.1));
  EXPECT_FALSE(extractor.describedWith(atOnce, 0));
  EXPECT_TRUE(extractor.describedWith(upright, 0));
  EXPECT_FALSE(extractor.describedWith(upright, turn));
}
