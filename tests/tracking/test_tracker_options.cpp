#include <slamdunk/tracking/TrackerOptions.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

using namespace slamdunk;

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

  mrpt::config::CConfigFileMemory typo("[tracker]\nwindow_sise = 4\n");
  EXPECT_THROW(b.loadFromConfigFile(typo, "tracker"), std::invalid_argument);
  mrpt::config::CConfigFileMemory bad("[tracker]\nratio_threshold = 1.5\n");
  EXPECT_THROW(b.loadFromConfigFile(bad, "tracker"), std::invalid_argument);
  mrpt::config::CConfigFileMemory negative("[tracker]\nkeypoint_scale_sigma = -0.1\n");
  EXPECT_THROW(b.loadFromConfigFile(negative, "tracker"), std::invalid_argument);
  // The narrowest prior may not be wider than the widest.
  mrpt::config::CConfigFileMemory inverted(
      "[tracker]\nvelocity_prior_sigma_deg = 6\nvelocity_prior_min_sigma_deg = 8\n");
  EXPECT_THROW(b.loadFromConfigFile(inverted, "tracker"), std::invalid_argument);
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

  mrpt::config::CConfigFileMemory typo("[local_map]\nwindow_sise = 4\n");
  EXPECT_THROW(b.loadFromConfigFile(typo, "local_map"), std::invalid_argument);
  mrpt::config::CConfigFileMemory bad("[local_map]\nwindow_size = 0\n");
  EXPECT_THROW(b.loadFromConfigFile(bad, "local_map"), std::invalid_argument);
  mrpt::config::CConfigFileMemory badPool("[local_map]\nknn_neighbours = 1\n");
  EXPECT_THROW(b.loadFromConfigFile(badPool, "local_map"), std::invalid_argument);
}

// An INI written before [local_map] existed fails naming the key's new section.
TEST(TrackerOptions, KeyMovedToLocalMapIsNamed) {
  mrpt::config::CConfigFileMemory old("[tracker]\nwindow_size = 4\n");
  TrackerOptions o;
  try {
    o.loadFromConfigFile(old, "tracker");
    FAIL() << "window_size accepted in [tracker]";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(
        std::string(e.what()).find("[tracker] window_size now belongs to section [local_map]"),
        std::string::npos)
        << e.what();
  }
}
