// Runs the evaluate-trajectory program on files written here.

#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/eval/TrajectoryMetrics.h>

#include <TestData.h>
#include <ToolTest.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>

using namespace slamdunk;
using namespace slamdunk::test;

namespace {

Trajectory circle(std::size_t n, double rate, double t0) {
  Trajectory traj;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / rate;
    Pose p = Pose::Identity();
    p.linear() = Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d::UnitY()).toRotationMatrix();
    p.translation() = Eigen::Vector3d(std::cos(0.3 * t), 0.1 * t, std::sin(0.3 * t));
    traj.push_back({t0 + t, p});
  }
  return traj;
}

}  // namespace

class EvaluateTrajectoryTool : public ToolTest {
 protected:
  EvaluateTrajectoryTool() : ToolTest("evaluate-trajectory") {}
  void SetUp() override {
    ToolTest::SetUp();
    gtPath = dir + "/gt.txt";
    estPath = dir + "/est.txt";
  }
  std::string gtPath, estPath;
};

TEST_F(EvaluateTrajectoryTool, HelpExplainsAndExitsZero) {
  const CommandResult r = run("--help");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("--max-dt"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--rpe-delta"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ATE"), std::string::npos) << r.output;
}

// The estimate is a noisy, rigidly moved copy of the ground truth plus 7 poses past its end;
// the JSON numbers must equal the library's and the counts must be right.
TEST_F(EvaluateTrajectoryTool, JsonMatchesLibrary) {
  const Trajectory gt = circle(600, 30.0, 1000.0);
  Trajectory est = circle(607, 30.0, 1000.0);
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.2, -3, 1);
  for (std::size_t k = 0; k < est.size(); ++k) {
    est[k].pose = T * est[k].pose;
    est[k].pose.translation() += 0.004 * Eigen::Vector3d(std::sin(k * 1.3), std::cos(k * 0.7), 0);
  }
  writeTumTrajectory(gtPath, gt, "test ground truth");
  writeTumTrajectory(estPath, est, "test estimate");
  // What the library computes on the same (rounded) file contents.
  const eval::TrajectoryEvaluation ref =
      eval::TrajectoryMetrics::evaluate(readTumTrajectory(gtPath), readTumTrajectory(estPath));
  ASSERT_TRUE(ref.rpe.valid);
  ASSERT_GT(ref.ate.stats.rmse, 1e-3);

  const CommandResult r = run("--json " + shellQuote(gtPath) + " " + shellQuote(estPath));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(r.output.front(), '{') << r.output;
  EXPECT_EQ(jsonValue(r.output, "pairs"), 600);
  EXPECT_EQ(jsonValue(r.output, "estimate_poses"), 607);
  EXPECT_EQ(jsonValue(r.output, "unmatched_estimate_poses"), 7);
  EXPECT_NEAR(jsonValue(r.output, "ate_rmse_m"), ref.ate.stats.rmse, 1e-8);
  EXPECT_NEAR(jsonValue(r.output, "ate_mean_m"), ref.ate.stats.mean, 1e-8);
  EXPECT_NEAR(jsonValue(r.output, "ate_median_m"), ref.ate.stats.median, 1e-8);
  EXPECT_NEAR(jsonValue(r.output, "ate_max_m"), ref.ate.stats.max, 1e-8);
  EXPECT_NEAR(jsonValue(r.output, "rpe_trans_rmse_m_per_s"), ref.rpe.translation.rmse, 1e-8);
  EXPECT_NEAR(jsonValue(r.output, "rpe_rot_rmse_deg_per_s"), ref.rpe.rotationDegrees.rmse, 1e-6);
  // The added noise has rms norm ~0.004 m; the optimal alignment can only do better than T^-1.
  EXPECT_LT(jsonValue(r.output, "ate_rmse_m"), 0.0045);
  // One rotation scale per camera axis, null where the library has none.
  const std::vector<double> scale = jsonArray(r.output, "rotation_scale_xyz");
  ASSERT_EQ(scale.size(), 3u) << r.output;
  int finiteAxes = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::isnan(ref.rpe.rotationScale[axis])) {
      EXPECT_TRUE(std::isnan(scale[axis])) << "axis " << axis << ": " << scale[axis];
    } else {
      ++finiteAxes;
      EXPECT_NEAR(scale[axis], ref.rpe.rotationScale[axis], 1e-8) << "axis " << axis;
    }
  }
  EXPECT_GE(finiteAxes, 1) << "the circle turns about at least one axis";
}

TEST_F(EvaluateTrajectoryTool, HumanReadableOutput) {
  const Trajectory gt = circle(300, 30.0, 5.0);
  writeTumTrajectory(gtPath, gt);
  const CommandResult r = run(shellQuote(gtPath) + " " + shellQuote(gtPath));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("rmse"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("pairs associated"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("300"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("deg/s"), std::string::npos) << r.output;
}

TEST_F(EvaluateTrajectoryTool, MalformedLineNamesFileAndLine) {
  writeTumTrajectory(gtPath, circle(100, 30.0, 0.0));
  std::ofstream(estPath) << "# estimate\n"
                         << "0.0 0 0 0 0 0 0 1\n"
                         << "0.033333 0 0 oops 0 0 0 1\n";
  const CommandResult r = run(shellQuote(gtPath) + " " + shellQuote(estPath));
  EXPECT_NE(r.exitCode, 0) << r.output;
  EXPECT_LT(r.exitCode, 128) << "crashed: " << r.output;
  EXPECT_NE(r.output.find(estPath + ":3"), std::string::npos) << r.output;
}

TEST_F(EvaluateTrajectoryTool, MissingFileIsAClearError) {
  writeTumTrajectory(gtPath, circle(100, 30.0, 0.0));
  const std::string missing = dir + "/no-such-estimate.txt";
  const CommandResult r = run(shellQuote(gtPath) + " " + shellQuote(missing));
  EXPECT_NE(r.exitCode, 0) << r.output;
  EXPECT_LT(r.exitCode, 128) << "crashed: " << r.output;
  EXPECT_NE(r.output.find(missing), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("does not exist"), std::string::npos) << r.output;
}

TEST_F(EvaluateTrajectoryTool, NoAssociatedPairsIsAClearError) {
  writeTumTrajectory(gtPath, circle(100, 30.0, 0.0));
  writeTumTrajectory(estPath, circle(100, 30.0, 500.0));
  const CommandResult r = run("--json " + shellQuote(gtPath) + " " + shellQuote(estPath));
  EXPECT_NE(r.exitCode, 0) << r.output;
  EXPECT_LT(r.exitCode, 128) << "crashed: " << r.output;
  EXPECT_NE(r.output.find("no pose pairs associated"), std::string::npos) << r.output;
}

TEST_F(EvaluateTrajectoryTool, TooFewPairsIsAClearError) {
  writeTumTrajectory(gtPath, circle(100, 30.0, 0.0));
  writeTumTrajectory(estPath, circle(2, 30.0, 0.0));
  const CommandResult r = run(shellQuote(gtPath) + " " + shellQuote(estPath));
  EXPECT_NE(r.exitCode, 0) << r.output;
  EXPECT_LT(r.exitCode, 128) << "crashed: " << r.output;
  EXPECT_NE(r.output.find("at least 3"), std::string::npos) << r.output;
}

TEST_F(EvaluateTrajectoryTool, ShortEstimateReportsRpeNotEnoughSpan) {
  writeTumTrajectory(gtPath, circle(100, 30.0, 0.0));
  writeTumTrajectory(estPath, circle(20, 30.0, 0.0));  // 0.63 s
  const CommandResult r = run("--json " + shellQuote(gtPath) + " " + shellQuote(estPath));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_LT(jsonValue(r.output, "ate_rmse_m"), 1e-6);
  EXPECT_TRUE(std::isnan(jsonValue(r.output, "rpe_trans_rmse_m_per_s"))) << r.output;
  EXPECT_NE(r.output.find("not enough span"), std::string::npos) << r.output;
}

TEST_F(EvaluateTrajectoryTool, BadOptionValueFails) {
  writeTumTrajectory(gtPath, circle(100, 30.0, 0.0));
  const CommandResult r = run("--max-dt -1 " + shellQuote(gtPath) + " " + shellQuote(gtPath));
  EXPECT_NE(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("--max-dt"), std::string::npos) << r.output;
}
