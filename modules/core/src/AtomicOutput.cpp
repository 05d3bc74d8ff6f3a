#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/ErrorText.h>

#include <fcntl.h>  // AT_FDCWD
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)
#include <sys/resource.h>
#include <unistd.h>

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/serialization/CSerializable.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace slamdunk {

namespace {
std::string makeTempName(const std::string& target, const char* kind = "tmp") {
  // Unique per process and per call, in the target's folder so rename() stays on one filesystem.
  static std::atomic<unsigned> counter{0};
  const fs::path t(target);
  const std::string name = "." + t.filename().string() + "." + kind + "-" +
                           std::to_string(::getpid()) + "-" + std::to_string(counter++);
  return (t.parent_path() / name).string();
}

std::string folderOf(const std::string& target) {
  const fs::path dir = fs::path(target).parent_path();
  return dir.empty() ? std::string(".") : dir.string();
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
  // An existing folder is swapped with the new one in one step where the filesystem allows it
  // (Linux renameat2, ext4/xfs/btrfs/tmpfs): a reader, or a process killed right here, finds
  // the old folder or the new one, never none. Elsewhere: removed, then renamed.
  if (fs::exists(target_, ec) &&
      ::renameat2(AT_FDCWD, temp_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0) {
    committed_ = true;
    fs::remove_all(temp_, ec);  // now the old folder
    return;
  }
  fs::remove_all(target_, ec);
  fs::rename(temp_, target_, ec);
  if (ec) throw std::runtime_error("cannot write folder '" + target_ + "': " + ec.message());
  committed_ = true;
}

StagedOutputs::~StagedOutputs() {
  if (committed_) return;
  std::error_code ec;
  for (const auto& f : files_) fs::remove(f.second, ec);
}

std::string StagedOutputs::stage(const std::string& target) {
  const std::string staged = makeTempName(target, "staged");
  files_.emplace_back(target, staged);
  return staged;
}

std::string StagedOutputs::stagePrefix(const std::string& prefix,
                                       const std::vector<std::string>& extensions) {
  const std::string staged = makeTempName(prefix, "staged");
  for (const std::string& ext : extensions) files_.emplace_back(prefix + ext, staged + ext);
  return staged;
}

void StagedOutputs::commit() {
  std::error_code ec;
  for (const auto& [target, staged] : files_)
    if (!fs::is_regular_file(staged, ec))
      throw std::runtime_error("nothing was written for '" + target + "'");
  for (const auto& [target, staged] : files_) {
    fs::rename(staged, target, ec);
    if (ec) throw std::runtime_error("cannot write '" + target + "': " + ec.message());
  }
  committed_ = true;
}

namespace {

bool sameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::equivalent(a, b, ec)) return true;  // both exist: hard and symbolic links too
  // An output that does not exist yet is the input only by name. Made absolute first: a
  // relative path none of whose parts exists would come back unchanged ("a" is not "./a").
  const auto resolved = [&ec](const std::string& p) {
    return fs::weakly_canonical(fs::absolute(p, ec), ec).lexically_normal();
  };
  const fs::path ca = resolved(a);
  if (ec) return false;
  const fs::path cb = resolved(b);
  return !ec && ca == cb;
}

}  // namespace

void rejectPathClashes(const std::vector<NamedPath>& inputs,
                       const std::vector<NamedPath>& outputs) {
  for (size_t o = 0; o < outputs.size(); ++o) {
    const NamedPath& out = outputs[o];
    if (out.path.empty()) continue;
    for (const NamedPath& in : inputs)
      if (!in.path.empty() && sameFile(out.path, in.path))
        throw std::invalid_argument(out.role + " '" + out.path + "' is the input " + in.role +
                                    " '" + in.path +
                                    "': writing it would replace that input; choose another path");
    for (size_t k = 0; k < o; ++k)
      if (!outputs[k].path.empty() && sameFile(out.path, outputs[k].path))
        throw std::invalid_argument(outputs[k].role + " and " + out.role + " name the same file '" +
                                    out.path + "': one would replace the other; choose two paths");
  }
}

void requireWritableFolder(const std::string& target) {
  const std::string dir = folderOf(target);
  if (!fs::is_directory(dir))
    throw std::runtime_error("output folder '" + dir + "' does not exist (for '" + target + "')");
  // access() answers for this process: a read-only mount fails it even for root, who may
  // write into a folder without write permission anyway.
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw std::runtime_error("output folder '" + dir + "' is not writable (for '" + target +
                             "'): " + std::strerror(errno));
}

void requireCompleteGzip(const std::string& path, uint64_t uncompressedBytes,
                         const std::string& target) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = f ? static_cast<std::streamoff>(f.tellg()) : -1;
  unsigned char trailer[4] = {0, 0, 0, 0};
  // 18 bytes: the smallest gzip file (10-byte header, empty deflate block, 8-byte trailer).
  if (size >= 18) {
    f.seekg(size - 4);
    f.read(reinterpret_cast<char*>(trailer), 4);
  }
  const uint32_t stored = uint32_t(trailer[0]) | uint32_t(trailer[1]) << 8 |
                          uint32_t(trailer[2]) << 16 | uint32_t(trailer[3]) << 24;
  if (size < 18 || !f || stored != static_cast<uint32_t>(uncompressedBytes))
    throw std::runtime_error("'" + target + "' was not written completely (" +
                             std::to_string(size < 0 ? 0 : size) +
                             " compressed bytes on disk, the end missing)");
}

void writeGzArchive(const std::string& path, const mrpt::serialization::CSerializable& object,
                    int compressionLevel) {
  AtomicOutput atomic(path);
  {
    mrpt::io::CFileGZOutputStream f;
    if (!f.open(atomic.tempPath(), compressionLevel))
      throw std::runtime_error("cannot open '" + path + "' for writing");
    mrpt::serialization::archiveFrom(f) << object;
    const uint64_t bytes = f.getPosition();
    f.close();
    requireCompleteGzip(atomic.tempPath(), bytes, path);
  }
  atomic.commit();
}

std::string writeFailureHint(const std::string& target) {
  const std::string dir = folderOf(target);
  std::string hint;
  std::error_code ec;
  const fs::space_info space = fs::space(dir, ec);
  if (!ec) hint = std::to_string(space.available / 1024) + " KiB free in '" + dir + "'";
  rlimit limit{};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    hint += (hint.empty() ? "" : ", ") + std::string("file size limit (ulimit -f) ") +
            std::to_string(limit.rlim_cur / 1024) + " KiB";
  return hint;
}

std::string withTargetName(std::string text, const std::string& staged, const std::string& target) {
  if (staged.empty()) return text;
  for (size_t at = text.find(staged); at != std::string::npos;
       at = text.find(staged, at + target.size()))
    text.replace(at, staged.size(), target);
  return text;
}

std::string writeErrorMessage(const std::string& target, const std::string& why,
                              const std::string& stagedAs) {
  const std::string text = withTargetName(summarizeError(why), stagedAs, target);
  const std::string hint = writeFailureHint(target);
  return "cannot write '" + target + "': " + text + (hint.empty() ? "" : " (" + hint + ")");
}

}  // namespace slamdunk
