#include "TestData.h"

#include <sys/wait.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>

namespace fs = std::filesystem;

namespace slamdunk::test {

std::string dataDir() {
  if (const char* env = std::getenv("SLAMDUNK_DATA_DIR"); env && *env) return env;
  return SLAMDUNK_DEFAULT_DATA_DIR;
}

namespace {
bool environmentFlag(const char* name) {
  const char* env = std::getenv(name);
  return env && std::string(env) == "1";
}
}  // namespace

bool prerequisitesRequired() { return environmentFlag("SLAMDUNK_REQUIRE_DATA"); }

bool longTestsEnabled() { return environmentFlag("SLAMDUNK_LONG_TESTS"); }

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
#ifdef SLAMDUNK_SANITIZED
  // A tool that a test expects to fail could fail from a sanitizer report instead and the test
  // would pass: any report in a tool's output fails the test. (scripts/sanitize.sh sends ASan's
  // reports to files and checks them too; GCC's UBSan, combined with ASan, always prints here.)
  for (const char* report : {"runtime error: ", "ERROR: AddressSanitizer", "ERROR: LeakSanitizer",
                             "WARNING: ThreadSanitizer"})
    if (r.output.find(report) != std::string::npos)
      ADD_FAILURE() << "sanitizer report from: " << commandLine << "\n" << r.output;
#endif
  return r;
}

std::string shellQuote(const std::string& s) { return "'" + s + "'"; }

std::string readFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::string preparedRawlog(const std::string& name) {
  const fs::path p = fs::path(SLAMDUNK_BINARY_DIR) / "test-data" / (name + ".rawlog");
  return fs::exists(p) ? p.string() : std::string();
}

std::string sharedRunDir(const std::string& name) {
  const fs::path p = fs::path(SLAMDUNK_BINARY_DIR) / "shared-runs" / name;
  return fs::exists(p / "output.txt") ? p.string() : std::string();
}

std::vector<std::string> tumPoseLines(const std::string& path) {
  std::istringstream in(readFile(path));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  return lines;
}

std::string groundTruthOf(const std::string& rawlog) {
  const fs::path p(rawlog);
  return (p.parent_path() / (p.stem().string() + "_groundtruth.txt")).string();
}

::testing::AssertionResult failedNaming(const CommandResult& run, const std::string& text) {
  if (run.exitCode != 1)
    return ::testing::AssertionFailure() << "exit code " << run.exitCode << ", not 1:\n"
                                         << run.output;
  if (run.output.find(text) == std::string::npos)
    return ::testing::AssertionFailure() << "the output does not name '" << text << "':\n"
                                         << run.output;
  return ::testing::AssertionSuccess();
}

std::vector<std::string> csvColumn(const std::string& path, const std::string& name) {
  auto split = [](const std::string& line) {
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    return fields;
  };
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  const auto header = split(line);
  const size_t k = std::find(header.begin(), header.end(), name) - header.begin();
  EXPECT_LT(k, header.size()) << "no column " << name << " in " << path;
  std::vector<std::string> column;
  while (std::getline(in, line)) {
    const auto fields = split(line);
    column.push_back(k < fields.size() ? fields[k] : "");
  }
  return column;
}

double jsonValue(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": *([-0-9.eE+]+)");
  std::smatch m;
  return std::regex_search(json, m, re) ? std::stod(m[1]) : std::nan("");
}

std::vector<double> jsonArray(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": *\\[([^\\]]*)\\]");
  std::smatch m;
  if (!std::regex_search(json, m, re)) return {};
  std::vector<double> out;
  std::stringstream items(m[1].str());
  std::string item;
  while (std::getline(items, item, ','))
    out.push_back(item.find("null") != std::string::npos ? std::nan("") : std::stod(item));
  return out;
}

}  // namespace slamdunk::test
