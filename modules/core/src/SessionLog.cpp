#include <slamdunk/core/SessionLog.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace slamdunk {

namespace {

/// TMPDIR as given, else /tmp: a TMPDIR that cannot be used makes the log stay in memory,
/// never write elsewhere.
std::string temporaryFolder() {
  const char* dir = std::getenv("TMPDIR");
  return dir && *dir ? dir : "/tmp";
}

}  // namespace

SpillFile::~SpillFile() {
  if (fd_ >= 0) ::close(fd_);
}

bool SpillFile::open() {
  const std::string dir = temporaryFolder();
#ifdef O_TMPFILE
  // Never visible in the folder: nothing to clean up, whatever ends the process.
  fd_ = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
  if (fd_ < 0) {  // a file system without O_TMPFILE: a named file, removed at once
    std::string name = dir + "/slamdunk-session-XXXXXX";
    fd_ = ::mkstemp(name.data());
    if (fd_ >= 0) ::unlink(name.c_str());
  }
  return fd_ >= 0;
}

bool SpillFile::append(const void* data, size_t bytes) {
  if (failed_) return false;
  if (fd_ < 0 && !open()) {
    failed_ = true;
    return false;
  }
  const auto* p = static_cast<const unsigned char*>(data);
  size_t written = 0;
  while (written < bytes) {
    const ssize_t n = ::pwrite(fd_, p + written, bytes - written, off_t(size_ + written));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {  // disk full or an I/O error: what was written of this chunk is ignored
      failed_ = true;
      return false;
    }
    written += size_t(n);
  }
  size_ += bytes;
  return true;
}

void SpillFile::read(size_t offset, void* out, size_t bytes) const {
  auto* p = static_cast<unsigned char*>(out);
  size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::pread(fd_, p + done, bytes - done, off_t(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw std::runtime_error("session log: cannot read back its temporary file in " +
                               temporaryFolder() + ": " +
                               (n < 0 ? std::string(std::strerror(errno)) : "file too short"));
    done += size_t(n);
  }
}

}  // namespace slamdunk
