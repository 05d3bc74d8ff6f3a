// Place recognition's parts on descriptors made up for the purpose: the words a vocabulary
// learns, the index's scores, and a loop found, verified and held back until consecutive
// keyframes agree.
#include <slamdunk/loop_closing/PlaceRecognition.h>

#include <gtest/gtest.h>

#include <random>

using namespace slamdunk;

namespace {

/// `count` descriptors drawn around `centres` random cluster centres (64 floats each).
cv::Mat clusteredDescriptors(int centres, int count, uint32_t seed, double spread = 0.02) {
  std::mt19937 random(seed);
  std::normal_distribution<float> noise(0.f, static_cast<float>(spread));
  std::uniform_real_distribution<float> uniform(-1.f, 1.f);
  cv::Mat c(centres, 64, CV_32F);
  for (int i = 0; i < c.rows; ++i)
    for (int d = 0; d < 64; ++d) c.at<float>(i, d) = uniform(random);
  cv::Mat out(count, 64, CV_32F);
  for (int r = 0; r < count; ++r)
    for (int d = 0; d < 64; ++d) out.at<float>(r, d) = c.at<float>(r % centres, d) + noise(random);
  return out;
}

/// A keyframe whose features are the given descriptors, their 3D points `points`.
KeyframePtr keyframe(KeyframeId id, const cv::Mat& descriptors,
                     const std::vector<Eigen::Vector3d>& points) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = id;
  kf->features.descriptors = descriptors.clone();
  kf->features.points = points;
  for (size_t i = 0; i < points.size(); ++i) kf->features.keypoints.emplace_back(1.f, 1.f, 8.f);
  return kf;
}

/// A scene of `n` points 1.5-3.5 m in front of the origin, each with its own descriptor.
struct Place {
  cv::Mat descriptors;
  std::vector<Eigen::Vector3d> points;  // in the world
};

Place place(int n, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> x(-1.5, 1.5), z(1.5, 3.5);
  Place p;
  p.descriptors = clusteredDescriptors(n, n, seed + 1000, 0.0);
  for (int i = 0; i < n; ++i) p.points.emplace_back(x(random), x(random), z(random));
  return p;
}

/// The place seen from a camera at `T_world_camera`: its points in the camera's frame, and its
/// descriptors slightly changed (another view).
KeyframePtr view(KeyframeId id, const Place& p, const Pose& T_world_camera, uint32_t seed) {
  std::mt19937 random(seed);
  std::normal_distribution<float> noise(0.f, 0.01f);
  cv::Mat d = p.descriptors.clone();
  for (int r = 0; r < d.rows; ++r)
    for (int c = 0; c < d.cols; ++c) d.at<float>(r, c) += noise(random);
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3d& w : p.points) points.push_back(T_world_camera.inverse() * w);
  return keyframe(id, d, points);
}

Pose translation(double x, double z) {
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(x, 0, z);
  return T;
}

/// A map built keyframe by keyframe, each linked to the one before (odometry) and handed to
/// place recognition: keyframe 0 sees place A, keyframes 1-6 other places at x = 1..6 m.
struct WalkFromA {
  explicit WalkFromA(const LoopClosingOptions& options, uint32_t firstOtherSeed)
      : recognition(options) {
    add(0, view(0, a, Pose::Identity(), 1), Pose::Identity());
    for (KeyframeId id = 1; id <= 6; ++id)
      away.push_back(add(id, view(id, place(300, firstOtherSeed + id - 1), Pose::Identity(), id),
                         translation(id, 0)));
  }
  /// Keyframe `id` linked to the one before, unless it starts a new component of the map.
  PlaceRecognition::Detection add(KeyframeId id, KeyframePtr kf, const Pose& pose,
                                  bool linked = true) {
    graph.addKeyframe(std::move(kf), pose);
    if (id > 0 && linked) {
      PointMatch m{Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1), 1.0};
      graph.addMatches(id - 1, id, {m, m, m});
    }
    return recognition.keyframeAdded(graph, id);
  }
  /// Place A again, seen from `truth` (relative to A's keyframe), where the map puts `mapPose`.
  PlaceRecognition::Detection backAtA(KeyframeId id, const Pose& truth, const Pose& mapPose) {
    return add(id, viewOfA(id, truth), mapPose);
  }
  /// Keyframe `id`'s view of place A from `truth`.
  KeyframePtr viewOfA(KeyframeId id, const Pose& truth) const {
    return view(id, a, truth, static_cast<uint32_t>(id));
  }

  PlaceRecognition recognition;
  KeyframeGraph graph;
  const Place a = place(300, 10);
  std::vector<PlaceRecognition::Detection> away;
};

LoopClosingOptions smallMapOptions() {
  LoopClosingOptions o;
  o.vocabularyKeyframes = 6;
  o.minHops = 3;
  return o;
}

}  // namespace

TEST(Vocabulary, SameSeedSameWordsAndDistinctDescriptorsDistinctWords) {
  const cv::Mat noisy = clusteredDescriptors(50, 2000, 1);
  const Vocabulary a = Vocabulary::learn(noisy, 8, 3, 5, 42);
  const Vocabulary b = Vocabulary::learn(noisy, 8, 3, 5, 42);
  EXPECT_LE(a.size(), 512u);
  EXPECT_GE(a.size(), 50u);
  EXPECT_EQ(a.words(noisy), b.words(noisy));
  // 50 descriptors, each 40 times: copies share a word, different descriptors never do.
  const cv::Mat copies = clusteredDescriptors(50, 2000, 2, 0.0);
  const std::vector<uint32_t> w = Vocabulary::learn(copies, 8, 3, 5, 42).words(copies);
  for (int r = 0; r < copies.rows; ++r) {
    EXPECT_EQ(w[r], w[r % 50]) << "row " << r;
    if (r < 50)
      for (int other = 0; other < r; ++other) EXPECT_NE(w[r], w[other]) << r << " " << other;
  }
  EXPECT_THROW(Vocabulary::learn(cv::Mat(), 8, 3, 5, 42), std::invalid_argument);
  EXPECT_THROW(a.words(cv::Mat(3, 32, CV_32F, cv::Scalar(0))), std::invalid_argument);
}

TEST(Vocabulary, BinaryDescriptorsAreClusteredAsBits) {
  // Squared distances between the bit rows are Hamming distances.
  const cv::Mat bytes = (cv::Mat_<uint8_t>(2, 2) << 0xFF, 0x00, 0x0F, 0x01);
  const cv::Mat bits = descriptorRowsAsFloat(bytes);
  ASSERT_EQ(bits.cols, 16);
  EXPECT_DOUBLE_EQ(cv::norm(bits.row(0), bits.row(1), cv::NORM_L2SQR),
                   cv::norm(bytes.row(0), bytes.row(1), cv::NORM_HAMMING));
}

TEST(PlaceIndex, ScoresOneForTheSameBagAndZeroForNothingShared) {
  const cv::Mat a = clusteredDescriptors(40, 400, 2);
  const cv::Mat b = clusteredDescriptors(40, 400, 3);  // other centres
  cv::Mat both;
  cv::vconcat(a, b, both);
  Vocabulary words = Vocabulary::learn(both, 10, 2, 5, 42);
  PlaceIndex index(words, {words.words(a), words.words(b)});
  index.add(1, index.describe(a));
  index.add(2, index.describe(b));
  EXPECT_NEAR(index.score(1, 1), 1.0, 1e-5);
  EXPECT_LT(index.score(1, 2), 0.1);
  const auto hits = index.query(index.describe(a.rowRange(0, 200)));
  ASSERT_FALSE(hits.empty());
  EXPECT_EQ(hits.front().first, 1u);
  EXPECT_GT(hits.front().second, 0.5);
  index.remove(1);
  EXPECT_FALSE(index.contains(1));
  EXPECT_EQ(index.score(1, 2), 0.0);
}

// A camera leaves place A, walks through other places, and comes back to A: the keyframes of
// the return verify a loop with A's keyframe, and the loop is accepted only at the second one
// that agrees with the first.
TEST(PlaceRecognition, AcceptsALoopOnceConsecutiveKeyframesAgree) {
  LoopClosingOptions o = smallMapOptions();
  o.consistentKeyframes = 2;
  WalkFromA walk(o, 20);
  for (const PlaceRecognition::Detection& d : walk.away) EXPECT_TRUE(d.accepted.empty());
  // The map's poses drifted by 0.3 m along x at the return.
  const PlaceRecognition::Detection first =
      walk.backAtA(7, translation(0.1, 0), translation(0.4, 0));
  EXPECT_TRUE(first.accepted.empty()) << "one keyframe alone must not close a loop";
  EXPECT_GE(first.candidatesVerified, 1);
  const PlaceRecognition::Detection second =
      walk.backAtA(8, translation(0.2, 0.1), translation(0.5, 0.1));
  ASSERT_EQ(second.accepted.size(), 2u);
  for (const LoopHypothesis& h : second.accepted) {
    EXPECT_EQ(h.candidate, 0u);
    EXPECT_GE(h.inliers.size(), 250u);
  }
  // The measured relative pose is the true one (0.1 m and 0.2 m along x), not the drifted map's.
  EXPECT_NEAR(second.accepted[0].T_candidate_query.translation().x(), 0.1, 0.005);
  EXPECT_NEAR(second.accepted[1].T_candidate_query.translation().x(), 0.2, 0.005);
  EXPECT_NEAR(second.accepted[1].T_candidate_query.translation().z(), 0.1, 0.005);
}

// The same return, but the second keyframe's loop disagrees with the first (a place that looks
// like A, seen from where A's geometry does not fit the odometry): nothing is accepted.
TEST(PlaceRecognition, LoopsThatDisagreeWithTheOdometryAreNotAccepted) {
  WalkFromA walk(smallMapOptions(), 21);
  EXPECT_EQ(walk.backAtA(7, translation(0.1, 0), translation(0.4, 0)).accepted.size(), 0u);
  // By the odometry the camera moved 0.1 m; by the loops, 1 m.
  EXPECT_EQ(walk.backAtA(8, translation(1.1, 0), translation(0.5, 0)).accepted.size(), 0u);
}

// Place A seen again where the map says the camera is 6 m from A after a 6.6 m walk: identical
// views, agreeing loops, but a correction no odometry drifts into (a second identical room).
TEST(PlaceRecognition, ALookAlikeFartherThanTheDriftIsAnotherPlace) {
  LoopClosingOptions o = smallMapOptions();
  WalkFromA walk(o, 21);
  EXPECT_EQ(walk.backAtA(7, translation(0.1, 0), translation(6.5, 0)).accepted.size(), 0u);
  EXPECT_EQ(walk.backAtA(8, translation(0.2, 0), translation(6.6, 0)).accepted.size(), 0u);
  // The same views where the map's drift is plausible are a loop (the test above).
  o.maxDriftShare = 1.0;
  PlaceRecognition lenient(o);
  KeyframeGraph again;
  size_t accepted = 0;
  for (KeyframeId id = 0; id <= 8; ++id) {
    again.addKeyframe(walk.graph.keyframe(id), walk.graph.pose(id));
    if (id > 0) {
      PointMatch m{Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1), 1.0};
      again.addMatches(id - 1, id, {m, m, m});
    }
    accepted += lenient.keyframeAdded(again, id).accepted.size();
  }
  EXPECT_EQ(accepted, 2u);
}

// A second component of the map (a session that started where the map does not reach) comes
// to place A: the map puts it 60 m away, and no path bounds the correction, so the join waits
// for three agreeing keyframes where a loop within one component needs two.
TEST(PlaceRecognition, JoiningAnotherComponentWaitsForMoreAgreeingKeyframes) {
  LoopClosingOptions o = smallMapOptions();
  o.consistentKeyframes = 2;
  o.joinConsistentKeyframes = 3;
  o.minHops = 5;  // the new component's own first keyframe is no candidate
  WalkFromA walk(o, 22);
  const Pose origin = translation(60, 0);  // the new component's first keyframe
  std::vector<PlaceRecognition::Detection> joining;
  for (KeyframeId id = 7; id <= 10; ++id) {
    const double walked = 0.1 * (id - 7);
    joining.push_back(walk.add(id, walk.viewOfA(id, translation(0.1 + walked, 0)),
                               origin * translation(walked, 0), id > 7));
  }
  EXPECT_EQ(joining[0].candidatesVerified, 0) << "a keyframe without neighbours has no baseline";
  for (int i = 1; i <= 2; ++i) {
    EXPECT_GE(joining[i].candidatesVerified, 1);
    EXPECT_TRUE(joining[i].accepted.empty()) << "keyframe " << 7 + i;
  }
  ASSERT_EQ(joining[3].accepted.size(), 3u);
  for (const LoopHypothesis& h : joining[3].accepted) {
    EXPECT_TRUE(h.joins);
    EXPECT_EQ(h.candidate, 0u);
  }
  EXPECT_NEAR(joining[3].accepted.back().T_candidate_query.translation().x(), 0.4, 0.005);
}

TEST(LoopClosingOptions, BadValuesAreNamed) {
  LoopClosingOptions o;
  o.minInliers = 2;
  try {
    o.validate();
    FAIL() << "min_inliers = 2 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("min_inliers"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("loop_closing"), std::string::npos) << e.what();
  }
}
