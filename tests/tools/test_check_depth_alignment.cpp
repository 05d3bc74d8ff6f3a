// check-depth-alignment on the synthetic loop (exact depth, exact ground truth): the ground
// truth agrees with its depth (rotation scale 1), a trajectory that turns 0.9 as far as the
// camera reads 1/0.9, and bad input is refused by name.

#include <slamdunk/core/TumTrajectory.h>

#include "TestData.h"
#include "ToolTest.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>

using namespace slamdunk;
using namespace slamdunk::test;

namespace {

/// The trajectory with every frame-to-frame turn scaled by `factor` (in the camera's frame),
/// positions unchanged: a trajectory that turns `factor` times as far as the camera did.
Trajectory turnedBy(const Trajectory& t, double factor) {
  Trajectory out = t;
  for (size_t k = 1; k < t.size(); ++k) {
    const Eigen::AngleAxisd step(
        Eigen::Matrix3d(t[k - 1].pose.linear().transpose() * t[k].pose.linear()));
    out[k].pose.linear() =
        out[k - 1].pose.linear() * Eigen::AngleAxisd(factor * step.angle(), step.axis()).matrix();
  }
  return out;
}

}  // namespace

class CheckDepthAlignmentTool : public ToolTest {
 protected:
  CheckDepthAlignmentTool() : ToolTest("check-depth-alignment") {}
};

TEST_F(CheckDepthAlignmentTool, GroundTruthAgreesWithItsDepth) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const CommandResult r =
      run("--json --every 20 " + shellQuote(rawlog) + " " + shellQuote(groundTruthOf(rawlog)));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_GE(jsonValue(r.output, "aligned"), 5) << r.output;
  const std::vector<double> scale = jsonArray(r.output, "rotation_scale_xyz");
  ASSERT_EQ(scale.size(), 3u) << r.output;
  ASSERT_FALSE(std::isnan(scale[1])) << "the loop turns about y: " << r.output;
  for (double s : scale)
    if (!std::isnan(s)) EXPECT_NEAR(s, 1.0, 0.005) << r.output;
  EXPECT_LT(jsonValue(r.output, "median_residual_aligned_mm"), 0.5) << r.output;
  EXPECT_LT(jsonValue(r.output, "rms_rotation_moved_deg"), 0.05) << r.output;
}

TEST_F(CheckDepthAlignmentTool, ATrajectoryThatTurnsTooLittleReadsMoreThanOne) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const std::string turned = dir + "/turned.txt";
  writeTumTrajectory(turned, turnedBy(readTumTrajectory(groundTruthOf(rawlog)), 0.9));
  const CommandResult r = run("--json --every 20 " + shellQuote(rawlog) + " " + shellQuote(turned));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const std::vector<double> scale = jsonArray(r.output, "rotation_scale_xyz");
  ASSERT_EQ(scale.size(), 3u) << r.output;
  EXPECT_NEAR(scale[1], 1 / 0.9, 0.02) << r.output;
  EXPECT_GT(jsonValue(r.output, "median_residual_given_mm"),
            5 * jsonValue(r.output, "median_residual_aligned_mm"))
      << r.output;
}

TEST_F(CheckDepthAlignmentTool, BadInputIsRefusedByName) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  CommandResult r = run(shellQuote(rawlog) + " " + shellQuote(dir + "/none.txt"));
  EXPECT_TRUE(test::failedNaming(r, "none.txt"));
  // A trajectory from another time: no frame has a pose, so no pair.
  const std::string elsewhere = dir + "/elsewhere.txt";
  Trajectory t = readTumTrajectory(groundTruthOf(rawlog));
  for (auto& p : t) p.timestamp += 1e5;
  writeTumTrajectory(elsewhere, t);
  r = run(shellQuote(rawlog) + " " + shellQuote(elsewhere));
  EXPECT_TRUE(test::failedNaming(r, "no frame pair was aligned"));
  r = run("--step 0 " + shellQuote(rawlog) + " " + shellQuote(elsewhere));
  EXPECT_TRUE(test::failedNaming(r, "--step"));
}
