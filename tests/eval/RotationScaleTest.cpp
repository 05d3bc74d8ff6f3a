// RotationScale: the least-squares factor between two sets of turns, per camera axis, and its
// standard error, against sums computed here independently.

#include <slamdunk/eval/RotationScale.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

using namespace slamdunk::eval;

namespace {
Eigen::Matrix3d turn(const Eigen::Vector3d& rotationVector) {
  const double angle = rotationVector.norm();
  if (angle == 0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotationVector / angle).toRotationMatrix();
}
}  // namespace

TEST(RotationScale, FactorAndStandardErrorPerAxis) {
  // Turns about x and y (3-5 degrees); none about z. The compared set turns 0.9 as far about
  // x and 1.1 as far about y, plus a scatter about y that the standard error must reflect.
  RotationScale scale;
  std::vector<double> ry, cy;
  for (int k = 0; k < 40; ++k) {
    const double ax = 0.06 * std::sin(0.7 * k), ay = 0.08 * std::cos(0.3 * k);
    const double scatter = 0.004 * std::sin(2.9 * k + 1);
    scale.add(turn({ax, ay, 0}), turn({0.9 * ax, 1.1 * ay + scatter, 0}));
    ry.push_back(ay);
    cy.push_back(1.1 * ay + scatter);
  }
  const Eigen::Vector3d s = scale.scale(), e = scale.standardError();
  EXPECT_EQ(scale.count(), 40u);
  // Rotation vectors of combined x and y turns are those vectors exactly (one axis-angle).
  EXPECT_NEAR(s.x(), 0.9, 1e-9);
  EXPECT_NEAR(e.x(), 0.0, 1e-6);
  double rc = 0, rr = 0;
  for (size_t k = 0; k < ry.size(); ++k) {
    rc += ry[k] * cy[k];
    rr += ry[k] * ry[k];
  }
  const double slope = rc / rr;
  double residual = 0;
  for (size_t k = 0; k < ry.size(); ++k) residual += std::pow(cy[k] - slope * ry[k], 2);
  EXPECT_NEAR(s.y(), slope, 1e-9);
  EXPECT_NEAR(e.y(), std::sqrt(residual / 39 / rr), 1e-7);
  EXPECT_GT(e.y(), 0.005);  // the scatter shows
  // No turn about z: no factor.
  EXPECT_TRUE(std::isnan(s.z()));
  EXPECT_TRUE(std::isnan(e.z()));
  EXPECT_NEAR(scale.referenceRmsDegrees().y(), std::sqrt(rr / 40) * 180 / M_PI, 1e-9);
}

TEST(RotationScale, NoPairsNoFactor) {
  const RotationScale empty;
  EXPECT_TRUE(empty.scale().array().isNaN().all());
  EXPECT_TRUE(empty.standardError().array().isNaN().all());
}
