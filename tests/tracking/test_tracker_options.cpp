#include <slamdunk/tracking/TrackerOptions.h>

#include "LoadError.h"
#include "TestData.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

using namespace slamdunk;
using ::testing::HasSubstr;

TEST(TrackerOptions, DefaultIniHasTable3Values) {
  mrpt::config::CConfigFile cfg(test::sourceDir() + "/config-ini/slamdunk-default.ini");
  TrackerOptions o;
  o.loadFromConfigFile(cfg, "tracker");
  o.localMap.loadFromConfigFile(cfg, "local_map");
  EXPECT_DOUBLE_EQ(o.localMap.windowSize, 5.0);    // W
  EXPECT_DOUBLE_EQ(o.localMap.windowShift, 0.25);  // T = 5% W
  EXPECT_DOUBLE_EQ(o.ratioThreshold, 0.8);
  EXPECT_EQ(o.keyframes.gridCols, 4);
  EXPECT_EQ(o.keyframes.gridRows, 4);
  EXPECT_EQ(o.keyframes.minInliersPerCell, 1);
  EXPECT_DOUBLE_EQ(o.keyframes.minOverlap, 0.8);
  EXPECT_EQ(o.loopHopThreshold, 3);
}

TEST(TrackerOptions, RoundTripAndErrors) {
  TrackerOptions a;
  a.ransac.seed = 99;
  a.keyframes.gridCols = 6;
  a.keypointScaleSigma = 0.25;
  a.adaptiveVelocityPrior = false;
  a.velocityPriorMinSigmaDegrees = 2.5;
  mrpt::config::CConfigFileMemory mem;
  a.saveToConfigFile(mem, "tracker");
  TrackerOptions b;
  b.loadFromConfigFile(mem, "tracker");
  EXPECT_EQ(b.ransac.seed, 99u);
  EXPECT_EQ(b.keyframes.gridCols, 6);
  EXPECT_DOUBLE_EQ(b.keypointScaleSigma, 0.25);
  EXPECT_FALSE(b.adaptiveVelocityPrior);
  EXPECT_DOUBLE_EQ(b.velocityPriorMinSigmaDegrees, 2.5);

  auto error = [](const std::string& text) {
    return test::loadError<TrackerOptions>("[tracker]\n" + text, "tracker");
  };
  EXPECT_THAT(error("ratio_treshold = 0.7\n"), HasSubstr("ratio_treshold"));
  EXPECT_THAT(error("ratio_threshold = 1.5\n"), HasSubstr("[tracker] ratio_threshold"));
  EXPECT_THAT(error("keypoint_scale_sigma = -0.1\n"), HasSubstr("keypoint_scale_sigma"));
  EXPECT_THAT(error("edge_information = scalar\n"),
              HasSubstr("'scalar' is not one of paper, isotropic or anisotropic"));
  // The narrowest prior may not be wider than the widest.
  EXPECT_THAT(error("velocity_prior_sigma_deg = 6\nvelocity_prior_min_sigma_deg = 8\n"),
              HasSubstr("must not exceed"));
  EXPECT_EQ(error("edge_information = Isotropic\n"), "");
}

TEST(LocalMapOptions, RoundTripAndErrors) {
  LocalMapOptions a;
  a.windowSize = 3.5;
  a.handoverFrames = 0;
  a.pool.seed = 11;
  a.pool.index = PoolIndexType::Exact;
  mrpt::config::CConfigFileMemory mem;
  a.saveToConfigFile(mem, "local_map");
  LocalMapOptions b;
  b.loadFromConfigFile(mem, "local_map");
  EXPECT_DOUBLE_EQ(b.windowSize, 3.5);
  EXPECT_EQ(b.handoverFrames, 0);
  EXPECT_EQ(b.pool.seed, 11u);
  EXPECT_EQ(b.pool.index, PoolIndexType::Exact);

  auto error = [](const std::string& text) {
    return test::loadError<LocalMapOptions>("[local_map]\n" + text, "local_map");
  };
  EXPECT_THAT(error("window_sise = 4\n"), HasSubstr("window_sise"));
  EXPECT_THAT(error("window_size = 0\n"), HasSubstr("[local_map] window_size must be > 0"));
  EXPECT_THAT(error("knn_neighbours = 1\n"), HasSubstr("knn_neighbours"));
  EXPECT_THAT(error("pool_index = kd-tree\n"),
              HasSubstr("not one of kdtree, flann, nanoflann or exact"));
}

// An INI written before [local_map] existed fails naming the key's new section.
TEST(TrackerOptions, KeyMovedToLocalMapIsNamed) {
  EXPECT_THAT(test::loadError<TrackerOptions>("[tracker]\nwindow_size = 4\n", "tracker"),
              HasSubstr("[tracker] window_size now belongs to section [local_map]"));
}
