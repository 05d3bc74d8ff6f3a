#pragma once
// A fixture for the tests of one of this project's command-line tools.

#include "TestData.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>

namespace slamdunk::test {

/// Each test skips (or fails, see SLAMDUNK_SKIP) when the tool is not built, and has a fresh
/// scratch folder `dir` named after it. Subclasses name the tool in their constructor.
class ToolTest : public ::testing::Test {
 protected:
  explicit ToolTest(std::string tool) : tool_(std::move(tool)) {}

  void SetUp() override {
    if (!std::ifstream(toolPath(tool_)).good())
      SLAMDUNK_SKIP("tool not built: " << toolPath(tool_));
    dir = scratchDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }

  /// The tool run with `args`, the rest of its shell command line (paths in shellQuote()).
  CommandResult run(const std::string& args) const {
    return runCommand(shellQuote(toolPath(tool_)) + " " + args);
  }

  std::string dir;

 private:
  std::string tool_;
};

}  // namespace slamdunk::test
