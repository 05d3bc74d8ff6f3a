#include <slamdunk/core/AtomicOutput.h>

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace slamdunk {

namespace {
std::string makeTempName(const std::string& target) {
  // Unique per process and per call, in the target's folder so rename() stays on one filesystem.
  static std::atomic<unsigned> counter{0};
  const fs::path t(target);
  const std::string name = "." + t.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                           "-" + std::to_string(counter++);
  return (t.parent_path() / name).string();
}
}  // namespace

AtomicOutput::AtomicOutput(std::string targetPath)
    : target_(std::move(targetPath)), temp_(makeTempName(target_)) {
  const fs::path dir = fs::path(target_).parent_path();
  if (!dir.empty() && !fs::is_directory(dir))
    throw std::runtime_error("output folder '" + dir.string() + "' does not exist (for '" +
                             target_ + "')");
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicOutput::commit() {
  std::error_code ec;
  if (!fs::exists(temp_, ec)) throw std::runtime_error("nothing was written for '" + target_ + "'");
  fs::rename(temp_, target_, ec);
  if (ec) throw std::runtime_error("cannot write '" + target_ + "': " + ec.message());
  committed_ = true;
}

AtomicOutputFolder::AtomicOutputFolder(std::string targetPath)
    : target_(std::move(targetPath)), temp_(makeTempName(target_)) {
  fs::remove_all(temp_);
  fs::create_directories(temp_);
}

AtomicOutputFolder::~AtomicOutputFolder() {
  std::error_code ec;
  if (!committed_) fs::remove_all(temp_, ec);
}

void AtomicOutputFolder::commit() {
  std::error_code ec;
  fs::remove_all(target_, ec);
  fs::rename(temp_, target_, ec);
  if (ec) throw std::runtime_error("cannot write folder '" + target_ + "': " + ec.message());
  committed_ = true;
}

}  // namespace slamdunk
