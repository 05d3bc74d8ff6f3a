#include <slamdunk/slam/SlamOptions.h>

#include "LoadError.h"
#include "TestData.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

using namespace slamdunk;
using ::testing::HasSubstr;

namespace {
std::string asText(const SlamOptions& o) {
  mrpt::config::CConfigFileMemory mem;
  o.saveToConfigFile(mem, "");
  return mem.getContent();
}
}  // namespace

// The shipped default INI documents the built-in defaults: loading it must change nothing.
TEST(SlamOptions, DefaultIniEqualsBuiltInDefaults) {
  const SlamOptions fromIni =
      SlamOptions::fromFile(test::sourceDir() + "/config-ini/slamdunk-default.ini");
  EXPECT_EQ(asText(fromIni), asText(SlamOptions()));
}

// The advanced INI lists every key, each at its built-in default.
TEST(SlamOptions, AdvancedIniListsEveryKeyAtItsDefault) {
  const std::string path = test::sourceDir() + "/config-ini/slamdunk-advanced.ini";
  EXPECT_EQ(asText(SlamOptions::fromFile(path)), asText(SlamOptions()));
  mrpt::config::CConfigFileMemory defaults;
  SlamOptions().saveToConfigFile(defaults, "");
  mrpt::config::CConfigFile advanced(path);
  std::vector<std::string> sections;
  defaults.getAllSections(sections);
  for (const std::string& section : sections) {
    std::vector<std::string> keys;
    defaults.getAllKeys(section, keys);
    for (const std::string& key : keys)
      EXPECT_TRUE(advanced.keyExists(section, key)) << "[" << section << "] " << key;
  }
}

TEST(SlamOptions, RoundTripThroughIni) {
  SlamOptions a;
  a.optimizerThread = true;
  a.optimizer.rings = 5;
  a.tracker.localMap.windowSize = 2.5;
  a.features.type = FeatureType::ORB;
  mrpt::config::CConfigFileMemory mem;
  a.saveToConfigFile(mem, "");
  SlamOptions b;
  b.loadFromConfigFile(mem, "");
  EXPECT_EQ(asText(a), asText(b));
  EXPECT_EQ(b.optimizer.rings, 5);
  EXPECT_TRUE(b.optimizerThread);
}

TEST(SlamOptions, UnknownSectionOrKeyIsNamed) {
  EXPECT_THAT(test::loadError<SlamOptions>("[trackr]\nwindow_size = 3\n", ""),
              HasSubstr("[trackr]"));
  EXPECT_THAT(test::loadError<SlamOptions>("[slam]\nglobal_pass = true\n", ""),
              HasSubstr("global_pass"));
  EXPECT_THAT(test::loadError<SlamOptions>("[features]\ntype = BRISK\n", ""),
              HasSubstr("[features] type = 'BRISK' is not one of SURF64, SURF128, SIFT or ORB"));
  EXPECT_THAT(test::loadError<SlamOptions>("[optimizer]\nrobust_loss = tukey\n", ""),
              HasSubstr("not one of none, huber or cauchy"));
  EXPECT_THROW(SlamOptions::fromFile("/nonexistent/pipeline.ini"), std::runtime_error);
}
