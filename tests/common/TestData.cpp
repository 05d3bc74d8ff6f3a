#include "TestData.h"

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace slamdunk::test {

std::string dataDir() {
  if (const char* env = std::getenv("SLAMDUNK_DATA_DIR"); env && *env) return env;
  return SLAMDUNK_DEFAULT_DATA_DIR;
}

std::string dataPath(const std::string& relative) {
  const fs::path p = fs::path(dataDir()) / relative;
  return fs::exists(p) ? p.string() : std::string();
}

std::string toolPath(const std::string& name) {
  return (fs::path(SLAMDUNK_BINARY_DIR) / "bin" / name).string();
}

std::string sourceDir() { return SLAMDUNK_SOURCE_DIR; }

std::string scratchDir(const std::string& testName) {
  const fs::path p = fs::path(SLAMDUNK_BINARY_DIR) / "test-scratch" / testName;
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

CommandResult runCommand(const std::string& commandLine) {
  CommandResult r;
  FILE* pipe = popen((commandLine + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

}  // namespace slamdunk::test
