// Outputs written so that nothing the user has is lost: atomic files and folders, staged
// outputs replaced together, the writable-folder check, the gzip completeness check and the
// messages of failed writes.

#include <slamdunk/core/AtomicOutput.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {
using test::readFile;
size_t entries(const std::string& dir) {
  return static_cast<size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

/// dir/out, a folder the user already has (holding old.txt): what an AtomicOutputFolder replaces.
std::string existingFolder(const std::string& dir) {
  const std::string folder = dir + "/out";
  fs::create_directories(folder);
  std::ofstream(folder + "/old.txt") << "old";
  return folder;
}
}  // namespace

TEST(StagedOutputs, ReplaceTheirTargetsTogetherOnlyOnCommit) {
  const std::string dir = test::scratchDir("StagedOutputs_Commit");
  std::ofstream(dir + "/a.txt") << "old a";
  {
    StagedOutputs out;
    std::ofstream(out.stage(dir + "/a.txt")) << "new a";
    const std::string prefix = out.stagePrefix(dir + "/cloud", {".ply", ".pcd"});
    std::ofstream(prefix + ".ply") << "ply";
    std::ofstream(prefix + ".pcd") << "pcd";
    EXPECT_EQ(readFile(dir + "/a.txt"), "old a");  // nothing replaced before commit()
    EXPECT_FALSE(fs::exists(dir + "/cloud.ply"));
    out.commit();
  }
  EXPECT_EQ(readFile(dir + "/a.txt"), "new a");
  EXPECT_EQ(readFile(dir + "/cloud.ply"), "ply");
  EXPECT_EQ(readFile(dir + "/cloud.pcd"), "pcd");
  EXPECT_EQ(entries(dir), 3u);  // no staged file left
}

TEST(StagedOutputs, AFailedRunReplacesNothingAndLeavesNothing) {
  const std::string dir = test::scratchDir("StagedOutputs_Failed");
  std::ofstream(dir + "/a.txt") << "old a";
  std::ofstream(dir + "/b.txt") << "old b";
  {
    StagedOutputs out;
    std::ofstream(out.stage(dir + "/a.txt")) << "new a";
    out.stage(dir + "/b.txt");  // its writer failed before creating it
    try {
      out.commit();
      FAIL() << "commit() with an output never written";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("b.txt"), std::string::npos) << e.what();
    }
  }  // never committed: the staged files go
  EXPECT_EQ(readFile(dir + "/a.txt"), "old a");
  EXPECT_EQ(readFile(dir + "/b.txt"), "old b");
  EXPECT_EQ(entries(dir), 2u);
}

TEST(AtomicOutputChecks, WritableFolder) {
  const std::string dir = test::scratchDir("AtomicOutput_Writable");
  EXPECT_NO_THROW(requireWritableFolder(dir + "/out.txt"));
  try {
    requireWritableFolder(dir + "/missing/out.txt");
    FAIL() << "a missing folder accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing' does not exist"), std::string::npos) << e.what();
  }
  std::ofstream(dir + "/file") << "x";
  EXPECT_THROW(requireWritableFolder(dir + "/file/out.txt"), std::runtime_error);
}

TEST(AtomicOutputChecks, CompleteGzipFilesPassCutOnesDoNot) {
  const std::string dir = test::scratchDir("AtomicOutput_Gzip");
  const std::string path = dir + "/data.gz";
  std::string text;
  for (int i = 0; i < 20000; ++i) text += std::to_string(i * 7919 % 10007) + " ";
  uint64_t bytes = 0;
  {
    mrpt::io::CFileGZOutputStream f(path);
    f.Write(text.data(), text.size());
    bytes = f.getPosition();  // what the writers pass: the uncompressed length
    f.close();
  }
  EXPECT_EQ(bytes, text.size());
  EXPECT_NO_THROW(requireCompleteGzip(path, bytes, "data"));
  // Wrong length (another file's), and the same file without its last bytes.
  EXPECT_THROW(requireCompleteGzip(path, bytes + 1, "data"), std::runtime_error);
  const std::string whole = readFile(path);
  std::ofstream(dir + "/cut.gz", std::ios::binary).write(whole.data(), whole.size() - 100);
  try {
    requireCompleteGzip(dir + "/cut.gz", bytes, dir + "/target.map");
    FAIL() << "a gzip file without its end accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("target.map' was not written completely"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(requireCompleteGzip(dir + "/missing.gz", bytes, "x"), std::runtime_error);
}

TEST(AtomicOutputChecks, WriteErrorMessageNamesTheTargetNotTheStagedFile) {
  const std::string dir = test::scratchDir("AtomicOutput_Message");
  const std::string target = dir + "/trajectory.txt", staged = dir + "/.trajectory.txt.staged-1-0";
  const std::string m =
      writeErrorMessage(target, "write error on trajectory file '" + staged + "'", staged);
  EXPECT_EQ(m.find(staged), std::string::npos) << m;
  EXPECT_NE(m.find("cannot write '" + target + "': write error on trajectory file '" + target),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("KiB free in '" + dir + "'"), std::string::npos) << m;
}

TEST(AtomicOutputFolder, ReplacesAnExistingFolderWhole) {
  const std::string dir = test::scratchDir("AtomicOutputFolder_Replace");
  const std::string target = existingFolder(dir);
  {
    AtomicOutputFolder out(target);
    std::ofstream(out.tempPath() + "/new.txt") << "new";
    EXPECT_TRUE(fs::exists(target + "/old.txt")) << "untouched until commit()";
    out.commit();
  }
  EXPECT_TRUE(fs::exists(target + "/new.txt"));
  EXPECT_FALSE(fs::exists(target + "/old.txt")) << "the old folder's files go with it";
  EXPECT_EQ(entries(dir), 1u) << "no temporary folder left beside the target";
}

TEST(AtomicOutputFolder, WithoutCommitTheTargetStaysAndTheTemporaryGoes) {
  const std::string dir = test::scratchDir("AtomicOutputFolder_NoCommit");
  const std::string target = existingFolder(dir);
  {
    AtomicOutputFolder out(target);
    std::ofstream(out.tempPath() + "/new.txt") << "new";
  }
  EXPECT_TRUE(fs::exists(target + "/old.txt"));
  EXPECT_FALSE(fs::exists(target + "/new.txt"));
  EXPECT_EQ(entries(dir), 1u);
}

TEST(AtomicOutputFolder, CreatesANewFolder) {
  const std::string dir = test::scratchDir("AtomicOutputFolder_New");
  AtomicOutputFolder out(dir + "/fresh");
  std::ofstream(out.tempPath() + "/a.txt") << "a";
  out.commit();
  EXPECT_TRUE(fs::exists(dir + "/fresh/a.txt"));
  EXPECT_EQ(entries(dir), 1u);
}

// An output naming an input's file (or another output's) is refused before the run: `-t GT.txt
// --gt GT.txt` would otherwise replace the user's ground truth with the run's trajectory.
TEST(AtomicOutputChecks, OutputsClashingWithInputsOrEachOtherAreRefused) {
  const std::string dir = test::scratchDir("PathClashes");
  const std::string gt = dir + "/gt.txt";
  std::ofstream(gt) << "precious\n";
  fs::create_directories(dir + "/sub");
  fs::create_symlink(gt, dir + "/link.txt");

  const auto clash = [&](const std::string& out) {
    try {
      rejectPathClashes({{"--gt", gt}, {"--config", ""}}, {{"--trajectory", out}});
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--gt"), std::string::npos) << e.what();
      return true;
    }
    return false;
  };
  EXPECT_TRUE(clash(gt));
  EXPECT_TRUE(clash(dir + "/sub/../gt.txt"));  // another spelling of the same path
  EXPECT_TRUE(clash(dir + "/link.txt"));       // a symbolic link to it
  EXPECT_FALSE(clash(dir + "/trajectory.txt"));
  EXPECT_FALSE(clash(""));  // not given

  // Two outputs: one would replace the other, whether or not the file exists yet.
  EXPECT_THROW(rejectPathClashes({}, {{"-t", dir + "/new.txt"}, {"-k", dir + "/./new.txt"}}),
               std::invalid_argument);
  EXPECT_NO_THROW(rejectPathClashes({}, {{"-t", dir + "/a.txt"}, {"-k", dir + "/b.txt"}}));
  EXPECT_EQ(readFile(gt), "precious\n");
}
