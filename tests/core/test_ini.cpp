#include <slamdunk/core/IniOptions.h>
#include <slamdunk/core/TumSequence.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

using namespace slamdunk;

namespace {
enum class Shade { Light, Dark, Grey };
}  // namespace

namespace slamdunk {
SLAMDUNK_ENUM_NAMES(Shade, {{Shade::Light, "light"},
                            {Shade::Dark, "dark"},
                            {Shade::Dark, "black"},
                            {Shade::Grey, "grey"}});
}  // namespace slamdunk

TEST(IniSectionReader, ReadsValuesWithCommentsAndDefaults) {
  mrpt::config::CConfigFileMemory cfg(
      "[s]\na = 2.5   // comment\nb = 7 # comment\nc = true\nv = [1 2, 3]\nname = orb\n");
  IniSectionReader r(cfg, "s");
  EXPECT_DOUBLE_EQ(r.readDouble("a", 0), 2.5);
  EXPECT_EQ(r.readInt("b", 0), 7);
  EXPECT_TRUE(r.readBool("c", false));
  EXPECT_EQ(r.readDoubles("v", {}, 3), (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(r.readString("name", ""), "orb");
  EXPECT_EQ(r.readInt("missing", 42), 42);
  EXPECT_NO_THROW(r.rejectUnknownKeys());
}

TEST(IniSectionReader, UnknownKeyIsNamed) {
  mrpt::config::CConfigFileMemory cfg("[tracker]\nratio_threshold = 0.8\nratio_treshold = 0.7\n");
  IniSectionReader r(cfg, "tracker");
  r.readDouble("ratio_threshold", 0.8);
  try {
    r.rejectUnknownKeys();
    FAIL() << "misspelled key accepted";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("ratio_treshold"), std::string::npos) << msg;
    EXPECT_NE(msg.find("[tracker]"), std::string::npos) << msg;
  }
}

TEST(IniSectionReader, MalformedValuesAreNamed) {
  mrpt::config::CConfigFileMemory cfg("[s]\na = 1.5x\nb = 2.5\nc = maybe\nv = 1 2\n");
  IniSectionReader r(cfg, "s");
  EXPECT_THROW(r.readDouble("a", 0), std::invalid_argument);
  EXPECT_THROW(r.readInt("b", 0), std::invalid_argument);
  EXPECT_THROW(r.readBool("c", false), std::invalid_argument);
  EXPECT_THROW(r.readDoubles("v", {}, 3), std::invalid_argument);
}

TEST(EnumNames, NamesReadBothWaysWithAliasesAndAnyCase) {
  EXPECT_EQ(enumFromName<Shade>("DARK"), Shade::Dark);
  EXPECT_EQ(enumFromName<Shade>("black"), Shade::Dark);
  EXPECT_EQ(enumFromName<Shade>("grey"), Shade::Grey);
  EXPECT_FALSE(enumFromName<Shade>("gre").has_value());
  EXPECT_FALSE(enumFromName<Shade>("greyish").has_value());
  EXPECT_STREQ(toString(Shade::Dark), "dark");
  EXPECT_STREQ(toString(static_cast<Shade>(7)), "?");
  EXPECT_EQ(enumChoices<Shade>(), "light, dark or grey");
}

TEST(IniSectionReader, EnumerationValuesAreNamesAndAWrongOneListsTheChoices) {
  mrpt::config::CConfigFileMemory cfg("[s]\nshade = Grey\nother = blue\n");
  IniSectionReader r(cfg, "s");
  Shade shade = Shade::Light, other = Shade::Light, missing = Shade::Dark;
  r("shade", shade);
  r("missing", missing);
  EXPECT_EQ(shade, Shade::Grey);
  EXPECT_EQ(missing, Shade::Dark);
  try {
    r("other", other);
    FAIL() << "a name outside the table was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "[s] other = 'blue' is not one of light, dark or grey");
  }

  mrpt::config::CConfigFileMemory out;
  IniSectionWriter w(out, "s");
  w("shade", Shade::Dark);
  EXPECT_EQ(out.read_string("s", "shade", ""), "dark");
}

TEST(CameraCalibration, ShippedCameraFilesLoad) {
  for (const char* name : {"tum-fr1", "tum-fr2", "tum-fr3", "7scenes", "generic-kinect"}) {
    const auto c = RgbdCameraCalibration::loadFromIni(test::sourceDir() + "/config-ini/cameras/" +
                                                      name + ".ini");
    EXPECT_EQ(c.intrinsics.width, 640) << name;
    EXPECT_GT(c.intrinsics.fx, 500) << name;
  }
  const auto fr1 =
      RgbdCameraCalibration::loadFromIni(test::sourceDir() + "/config-ini/cameras/tum-fr1.ini");
  EXPECT_DOUBLE_EQ(fr1.intrinsics.dist[4], 1.1633);
  EXPECT_DOUBLE_EQ(fr1.depthFactor, 5000);
  EXPECT_DOUBLE_EQ(fr1.stampLatencyMs, 12);
  EXPECT_DOUBLE_EQ(fr1.exposureTime(100.0), 99.988);
  const auto s7 =
      RgbdCameraCalibration::loadFromIni(test::sourceDir() + "/config-ini/cameras/7scenes.ini");
  EXPECT_DOUBLE_EQ(s7.depthFactor, 1000);
  EXPECT_DOUBLE_EQ(s7.stampLatencyMs, 0);  // its stamps are frame numbers / 30 Hz
}

TEST(CameraCalibration, StampLatencyBeyond100MsIsRejected) {
  mrpt::config::CConfigFileMemory cfg("[CAMERA]\nfx = 500\nfy = 500\nstamp_latency_ms = 250\n");
  try {
    RgbdCameraCalibration::loadFromConfig(cfg);
    FAIL() << "a 250 ms latency was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("stamp_latency_ms"), std::string::npos) << e.what();
  }
}

TEST(CameraCalibration, UnknownKeyInCameraFile) {
  mrpt::config::CConfigFileMemory cfg("[CAMERA]\nfx = 500\nfy = 500\ndepth_factr = 5000\n");
  EXPECT_THROW(RgbdCameraCalibration::loadFromConfig(cfg), std::invalid_argument);
  EXPECT_THROW(RgbdCameraCalibration::loadFromIni("/nonexistent/cam.ini"), std::runtime_error);
}
