// The motion model's measured error, which sets the width of each frame's velocity prior: it
// must come out as the spread of the errors it is given (per axis, translation and rotation
// apart), forget what left its window, and say nothing until it has seen enough frames.
#include <slamdunk/tracking/MotionModelError.h>

#include <gtest/gtest.h>

#include <limits>
#include <random>

using namespace slamdunk;

namespace {
Twist randomTwist(std::mt19937& rng, double metresPerSecond, double radiansPerSecond) {
  std::normal_distribution<double> g(0, 1);
  Twist t;
  for (int i = 0; i < 3; ++i) t(i) = metresPerSecond * g(rng);
  for (int i = 3; i < 6; ++i) t(i) = radiansPerSecond * g(rng);
  return t;
}
}  // namespace

TEST(MotionModelError, IsTheSpreadOfThePredictionErrorsPerAxis) {
  MotionModelError error(2000, 10);
  std::mt19937 rng(5);
  for (int i = 0; i < 2000; ++i) {
    const Twist truth = randomTwist(rng, 0.5, 1.0);  // whatever the camera does
    error.add(truth + randomTwist(rng, 0.02, 0.05), truth);
  }
  const auto sigma = error.sigma();
  ASSERT_TRUE(sigma);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR((*sigma)(i), 0.02, 0.001);
  for (int i = 3; i < 6; ++i) EXPECT_NEAR((*sigma)(i), 0.05, 0.0025);
}

TEST(MotionModelError, RemembersOnlyItsWindow) {
  MotionModelError error(30, 10);
  std::mt19937 rng(6);
  for (int i = 0; i < 200; ++i) error.add(randomTwist(rng, 0.3, 1.0), Twist::Zero());    // a shake
  for (int i = 0; i < 30; ++i) error.add(randomTwist(rng, 0.003, 0.01), Twist::Zero());  // calm
  const auto sigma = error.sigma();
  ASSERT_TRUE(sigma);
  EXPECT_EQ(error.samples(), 30u);
  EXPECT_LT((*sigma)(0), 0.006);
  EXPECT_LT((*sigma)(3), 0.02);
}

TEST(MotionModelError, SaysNothingBeforeEnoughFramesAndSkipsNonFiniteOnes) {
  MotionModelError error(30, 10);
  Twist broken = Twist::Zero();
  broken(4) = std::numeric_limits<double>::quiet_NaN();
  error.add(broken, Twist::Zero());
  for (int i = 0; i < 9; ++i) error.add(Twist::Constant(0.01), Twist::Zero());
  EXPECT_EQ(error.samples(), 9u);
  EXPECT_FALSE(error.sigma());
  error.add(Twist::Constant(0.01), Twist::Zero());
  const auto sigma = error.sigma();
  ASSERT_TRUE(sigma);
  EXPECT_DOUBLE_EQ((*sigma)(0), 0.01);
  EXPECT_DOUBLE_EQ((*sigma)(5), 0.01);
}
