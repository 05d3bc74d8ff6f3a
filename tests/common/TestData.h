#pragma once
// Where tests find real recordings and the project's own tools.

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace slamdunk::test {

/// $SLAMDUNK_DATA_DIR if set, else <source>/../shared/data.
std::string dataDir();
/// dataDir() + "/" + relative; empty string if it does not exist.
std::string dataPath(const std::string& relative);
/// <build>/bin/<name>: command-line tools built by this project.
std::string toolPath(const std::string& name);
std::string sourceDir();
/// A fresh, empty scratch folder for one test (under the build tree).
std::string scratchDir(const std::string& testName);

struct CommandResult {
  int exitCode = -1;
  std::string output;  ///< stdout and stderr together
};
/// Runs a shell command line and captures its output and exit code.
CommandResult runCommand(const std::string& commandLine);

/// A run refused as bad input should be: exit code 1 and `text` (what names the problem) in its
/// output. The failure message shows the whole output.
::testing::AssertionResult failedNaming(const CommandResult& run, const std::string& text);

/// Single-quoted for a shell command line.
std::string shellQuote(const std::string& s);

/// A file's whole content (empty when it cannot be read).
std::string readFile(const std::string& path);

/// <build>/test-data/<name>.rawlog made by the prepare_test_data fixture; empty if absent.
std::string preparedRawlog(const std::string& name);
/// "<dir>/<stem>_groundtruth.txt" beside a rawlog (as tum2rawlog and synthetic-rgbd write it).
std::string groundTruthOf(const std::string& rawlog);
/// The output folder of a SLAM run that several tests share (a setup test of the CTest fixture
/// shared_runs, tests/apps/CMakeLists.txt), or "" when it was not made.
std::string sharedRunDir(const std::string& name);
/// The lines of a TUM trajectory file that hold poses (its comments left out).
std::vector<std::string> tumPoseLines(const std::string& path);
/// A number from a tool's --json output; NaN when the key is absent.
double jsonValue(const std::string& json, const std::string& key);
/// The numbers of a one-line JSON array of numbers (null read as NaN); empty when the key is
/// absent.
std::vector<double> jsonArray(const std::string& json, const std::string& key);

/// One column of a CSV file with a header line (a frame log), by its header name; an empty
/// field where a row is short. Fails the test when the header has no such column.
std::vector<std::string> csvColumn(const std::string& path, const std::string& name);

/// True when SLAMDUNK_REQUIRE_DATA=1 (as in CI): a test whose prerequisites (the shared data,
/// a tool, an X server) are missing fails instead of skipping, so that a clone that cannot see
/// them is never green.
bool prerequisitesRequired();

/// True when SLAMDUNK_LONG_TESTS=1 (scripts/test-long.sh): tests then also run the variants CI
/// leaves out for time (the same code on a second, longer or differently degraded input).
bool longTestsEnabled();

}  // namespace slamdunk::test

/// Skips the current test with `message` (a `<<` chain), or fails it with the same message
/// when prerequisitesRequired().
#define SLAMDUNK_SKIP(message)                                                                \
  do {                                                                                        \
    if (::slamdunk::test::prerequisitesRequired())                                            \
      FAIL() << message << " [SLAMDUNK_REQUIRE_DATA=1: a missing prerequisite is a failure]"; \
    else                                                                                      \
      GTEST_SKIP() << message;                                                                \
  } while (0)

/// Skips (or fails, see SLAMDUNK_SKIP) the current test when a prepared rawlog is missing
/// (its source data is absent).
#define REQUIRE_RAWLOG(var, name)                                                         \
  const std::string var = ::slamdunk::test::preparedRawlog(name);                         \
  if (var.empty())                                                                        \
  SLAMDUNK_SKIP("rawlog '" << name << "' was not prepared (its source data is not under " \
                           << ::slamdunk::test::dataDir() << ")")

/// Skips (or fails, see SLAMDUNK_SKIP) the current test when a shared run (sharedRunDir) was
/// not made; `var` is its output folder.
#define REQUIRE_SHARED_RUN_DIR(var, name)                       \
  const std::string var = ::slamdunk::test::sharedRunDir(name); \
  if (var.empty())                                              \
  SLAMDUNK_SKIP("the shared run '" << name << "' was not made (test shared_run_" << name << ")")

/// Skips (or fails, see SLAMDUNK_SKIP) the current test when a dataset folder/file is missing.
#define SLAMDUNK_REQUIRE_DATA(var, relative)                                                     \
  const std::string var = ::slamdunk::test::dataPath(relative);                                  \
  if (var.empty())                                                                               \
  SLAMDUNK_SKIP("test data '" << relative << "' not found under " << ::slamdunk::test::dataDir() \
                              << " (set SLAMDUNK_DATA_DIR to the shared data folder)")
