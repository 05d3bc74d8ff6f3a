#pragma once
// An append-only log of a session: one entry per frame (its record, its timings, its latency),
// kept for as long as the session runs, in constant memory. Only the newest entries (one chunk)
// stay in memory; each full chunk goes to an unnamed temporary file, which is read back when
// the log is walked (at a checkpoint, at the end). A live session runs for hours: every entry
// kept in memory made its resident memory grow with the session (a 30-minute soak: 37 MB an
// hour for the records alone), where the file costs a few kilobytes a second of disk writes.
//
// When the temporary file cannot be created or written (no space left, no temporary folder),
// the entries simply stay in memory: nothing is lost, only the memory bound is.

#include <cstddef>
#include <cstring>
#include <memory>
#include <optional>
#include <type_traits>
#include <vector>

namespace slamdunk {

/// How an entry is stored in the file: kBytes bytes, written by encode and read by decode.
/// This default copies the bytes of a trivially copyable type; specialise it for others.
template <class T, class = void>
struct SessionLogCodec {
  static_assert(std::is_trivially_copyable_v<T>,
                "SessionLog<T>: specialise SessionLogCodec<T> for this type");
  static constexpr size_t kBytes = sizeof(T);
  static void encode(const T& entry, unsigned char* out) { std::memcpy(out, &entry, kBytes); }
  static T decode(const unsigned char* in) {
    T entry;
    std::memcpy(&entry, in, kBytes);
    return entry;
  }
};

/// An unnamed temporary file (in TMPDIR, else /tmp) that grows by appends and is read by
/// offset; deleted by the system when closed, even after a crash.
class SpillFile {
 public:
  SpillFile() = default;
  ~SpillFile();
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  /// Appends `bytes` bytes; false (and the file's size unchanged) when the file could not be
  /// created or written, and for every call after that.
  bool append(const void* data, size_t bytes);
  /// Reads `bytes` bytes at `offset`, within what append() wrote; throws std::runtime_error
  /// naming the file's folder if the system fails to read them back.
  void read(size_t offset, void* out, size_t bytes) const;
  size_t size() const { return size_; }

 private:
  bool open();
  int fd_ = -1;
  bool failed_ = false;
  size_t size_ = 0;
};

template <class T>
class SessionLog {
  using Codec = SessionLogCodec<T>;

 public:
  /// Entries kept in memory before they go to the file (with their encoding: 1024 frame
  /// records are 147 KB in memory and 112 KB in the file, written in one call).
  static constexpr size_t kChunk = 1024;

  SessionLog() { recent_.reserve(kChunk); }
  SessionLog(const SessionLog& other) : SessionLog() { append(other); }
  SessionLog& operator=(const SessionLog& other) {
    if (this != &other) {
      SessionLog copy(other);
      swap(copy);
    }
    return *this;
  }
  SessionLog(SessionLog&&) = default;
  SessionLog& operator=(SessionLog&&) = default;

  void push_back(const T& entry) {
    recent_.push_back(entry);
    if (recent_.size() >= kChunk && spillable_) spill();
  }
  template <class Iterator>
  void append(Iterator first, Iterator last) {
    for (; first != last; ++first) push_back(*first);
  }
  void append(const SessionLog& other) {
    other.forEach([this](const T& entry) { push_back(entry); });
  }

  size_t size() const { return spilled_ + recent_.size(); }
  /// Of size(), the entries in memory: fewer than kChunk unless the file failed.
  size_t entriesInMemory() const { return recent_.size(); }
  bool empty() const { return size() == 0; }
  /// The newest entry (the log must not be empty).
  const T& back() const { return recent_.empty() ? *lastSpilled_ : recent_.back(); }
  /// The entry `fromNewest` entries before the newest (0: the newest), to correct a recent
  /// entry in place; nullptr when it is not in memory (gone to the file, or no such entry).
  T* recent(size_t fromNewest) {
    return fromNewest < recent_.size() ? &recent_[recent_.size() - 1 - fromNewest] : nullptr;
  }

  /// Calls visit(entry) for every entry, oldest first.
  template <class Visit>
  void forEach(Visit&& visit) const {
    if (spilled_ > 0) {
      std::vector<unsigned char> buffer(kChunk * Codec::kBytes);
      for (size_t first = 0; first < spilled_; first += kChunk) {
        const size_t n = std::min(kChunk, spilled_ - first);
        file_->read(first * Codec::kBytes, buffer.data(), n * Codec::kBytes);
        for (size_t i = 0; i < n; ++i) visit(Codec::decode(buffer.data() + i * Codec::kBytes));
      }
    }
    for (const T& entry : recent_) visit(entry);
  }

  /// Every entry, in order, as a vector (for what needs them all at once, like percentiles).
  std::vector<T> toVector() const {
    std::vector<T> out;
    out.reserve(size());
    forEach([&](const T& entry) { out.push_back(entry); });
    return out;
  }

 private:
  void spill() {
    if (!file_) file_ = std::make_unique<SpillFile>();
    std::vector<unsigned char>& buffer = encodeBuffer_;
    buffer.resize(recent_.size() * Codec::kBytes);
    for (size_t i = 0; i < recent_.size(); ++i)
      Codec::encode(recent_[i], buffer.data() + i * Codec::kBytes);
    if (!file_->append(buffer.data(), buffer.size())) {
      spillable_ = false;  // keep everything in memory from now on
      return;
    }
    spilled_ += recent_.size();
    lastSpilled_ = recent_.back();
    recent_.clear();  // the capacity stays: no allocation per chunk
  }
  void swap(SessionLog& other) {
    std::swap(recent_, other.recent_);
    std::swap(file_, other.file_);
    std::swap(spilled_, other.spilled_);
    std::swap(lastSpilled_, other.lastSpilled_);
    std::swap(spillable_, other.spillable_);
    std::swap(encodeBuffer_, other.encodeBuffer_);
  }

  std::vector<T> recent_;            ///< the entries after the spilled ones
  std::unique_ptr<SpillFile> file_;  ///< created at the first spill
  size_t spilled_ = 0;               ///< entries in the file, the oldest ones
  std::optional<T> lastSpilled_;     ///< for back() right after a spill
  bool spillable_ = true;            ///< false once the file failed
  std::vector<unsigned char> encodeBuffer_;
};

}  // namespace slamdunk
