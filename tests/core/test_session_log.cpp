// SessionLog keeps a session's per-frame entries in constant memory: the newest chunk in
// memory, the rest in a temporary file. Every entry comes back, in order, bit for bit; when the
// file cannot be written, the entries stay in memory and nothing is lost.

#include <slamdunk/core/SessionLog.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

using namespace slamdunk;

namespace {

struct Timing {
  double total;
  int frame;
};

std::vector<Timing> entriesOf(const SessionLog<Timing>& log) {
  std::vector<Timing> out;
  log.forEach([&](const Timing& t) { out.push_back(t); });
  return out;
}

void expectEntries(const SessionLog<Timing>& log, int n) {
  ASSERT_EQ(log.size(), size_t(n));
  const auto entries = entriesOf(log);
  ASSERT_EQ(entries.size(), size_t(n));
  for (int i = 0; i < n; ++i) {
    ASSERT_EQ(entries[i].frame, i);
    ASSERT_EQ(entries[i].total, 0.1 * i);  // bit for bit
  }
  if (n > 0) EXPECT_EQ(log.back().frame, n - 1);
}

/// TMPDIR set for the scope of one test.
class TemporaryFolder {
 public:
  explicit TemporaryFolder(const char* dir) {
    if (const char* old = std::getenv("TMPDIR")) old_ = old;
    setenv("TMPDIR", dir, 1);
  }
  ~TemporaryFolder() {
    if (old_.empty())
      unsetenv("TMPDIR");
    else
      setenv("TMPDIR", old_.c_str(), 1);
  }

 private:
  std::string old_;
};

}  // namespace

TEST(SessionLog, EveryEntryComesBackInOrderAcrossChunks) {
  constexpr size_t kChunk = SessionLog<Timing>::kChunk;
  SessionLog<Timing> log;
  EXPECT_TRUE(log.empty());
  // Two chunks and a half: two go to the file; back() right after a spill, and after more.
  for (int i = 0; i < int(2 * kChunk); ++i) log.push_back({0.1 * i, i});
  expectEntries(log, int(2 * kChunk));
  for (int i = int(2 * kChunk); i < int(2 * kChunk + kChunk / 2); ++i) log.push_back({0.1 * i, i});
  expectEntries(log, int(2 * kChunk + kChunk / 2));
  EXPECT_EQ(log.entriesInMemory(), kChunk / 2);  // the rest is in the file
  EXPECT_EQ(log.toVector().size(), log.size());

  // Copies and assignments have every entry too, and stay independent of the original.
  SessionLog<Timing> copy(log);
  expectEntries(copy, int(log.size()));
  SessionLog<Timing> assigned;
  assigned.push_back({0, 0});
  assigned = copy;
  expectEntries(assigned, int(log.size()));
  copy.push_back({0.1 * double(log.size()), int(log.size())});
  expectEntries(copy, int(log.size() + 1));
  expectEntries(log, int(2 * kChunk + kChunk / 2));
}

TEST(SessionLog, WithoutATemporaryFolderEntriesStayInMemory) {
  TemporaryFolder missing("/nonexistent/slamdunk-session-log-test");
  SessionLog<Timing> log;
  const int n = int(3 * SessionLog<Timing>::kChunk + 7);
  for (int i = 0; i < n; ++i) log.push_back({0.1 * i, i});
  expectEntries(log, n);
  EXPECT_EQ(log.entriesInMemory(), size_t(n));
}
