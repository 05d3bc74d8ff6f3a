#include <slamdunk/slam/SlamOptions.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

using namespace slamdunk;

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
  mrpt::config::CConfigFileMemory section("[trackr]\nwindow_size = 3\n");
  SlamOptions o;
  try {
    o.loadFromConfigFile(section, "");
    FAIL() << "unknown section accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("[trackr]"), std::string::npos) << e.what();
  }
  mrpt::config::CConfigFileMemory key("[slam]\nglobal_pass = true\n");
  EXPECT_THROW(o.loadFromConfigFile(key, ""), std::invalid_argument);
  EXPECT_THROW(SlamOptions::fromFile("/nonexistent/pipeline.ini"), std::runtime_error);
}
