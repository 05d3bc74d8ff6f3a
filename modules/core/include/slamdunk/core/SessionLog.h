#pragma once
// An append-only log of a session: one entry per frame (its record, its timings, its latency),
// kept for as long as the session runs. The entries are stored in large buffers of the log's
// own, not in small blocks from the general heap: a live session allocates and frees many
// small objects every frame, and small blocks that are never freed, placed between them, keep
// the heap from ever returning their neighbours' memory (a 30-minute soak: memory grew 20 %
// faster than the entries themselves).

#include <cstddef>
#include <deque>
#include <memory_resource>

namespace slamdunk {

template <class T>
class SessionLog {
 public:
  SessionLog() : entries_(&buffers_) {}
  SessionLog(const SessionLog& other) : SessionLog() { append(other); }
  SessionLog& operator=(const SessionLog& other) {
    if (this != &other) {
      entries_.clear();  // the buffers stay: a log is assigned once, if at all
      append(other);
    }
    return *this;
  }

  void push_back(const T& entry) { entries_.push_back(entry); }
  template <class Iterator>
  void append(Iterator first, Iterator last) {
    entries_.insert(entries_.end(), first, last);
  }
  void append(const SessionLog& other) { append(other.begin(), other.end()); }

  size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  const T& back() const { return entries_.back(); }
  const T& operator[](size_t i) const { return entries_[i]; }
  auto begin() const { return entries_.begin(); }
  auto end() const { return entries_.end(); }

 private:
  static constexpr size_t kFirstBuffer = 64 * 1024;  ///< bytes; each next buffer is larger
  std::pmr::monotonic_buffer_resource buffers_{kFirstBuffer};
  std::pmr::deque<T> entries_;
};

}  // namespace slamdunk
