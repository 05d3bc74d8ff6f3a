// Outputs that cannot be written: a read-only output folder, a full disk (a small tmpfs) and a
// file size limit (RLIMIT_FSIZE, "ulimit -f"). Each must give a clear error naming the output,
// a non-zero exit code, and leave the files already in the folder byte-identical, with no
// temporary file left behind.
//
// slamdunk-rawlog replaces its outputs all together or not at all (a run can be repeated; its
// files belong together). slamdunk-live writes every output it can (a session cannot be
// repeated): those that fail keep their earlier version and are named.
//
// How, as root in a container: chmod does not stop root, so the read-only folder is a read-only
// bind mount, and the full disk a tmpfs of a few dozen KiB. Both are mounted inside a mount
// namespace of this test process's own (unshare), so they are invisible to everything else and
// vanish with the process even if it crashes; the apps it starts inherit them. Where mounting
// is not allowed the tmpfs test is skipped with the reason; not as root, the read-only folder is
// a folder without write permission. The file size limit needs no privilege: the apps run under
// "ulimit -f" with SIGXFSZ ignored, so a write past the limit fails with EFBIG as a write to a
// full disk fails with ENOSPC.

#include <slamdunk/core/TumTrajectory.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

using test::readFile;

/// Every file in a folder: name -> content.
std::map<std::string, std::string> snapshot(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir))
    files[e.path().filename().string()] = readFile(e.path().string());
  return files;
}

/// "Earlier files": a marker for each name, in `dir` (created if need be); returns the snapshot.
std::map<std::string, std::string> writeEarlierFiles(const std::string& dir,
                                                     const std::vector<std::string>& names) {
  fs::create_directories(dir);
  for (const auto& n : names) std::ofstream(dir + "/" + n) << "earlier " << n << ", keep me\n";
  return snapshot(dir);
}

void expectUnchanged(const std::map<std::string, std::string>& before, const std::string& dir) {
  const auto after = snapshot(dir);
  for (const auto& [name, content] : before) {
    const auto it = after.find(name);
    if (it == after.end())
      ADD_FAILURE() << name << " was deleted";
    else
      EXPECT_EQ(it->second, content) << name << " was changed";
  }
  for (const auto& [name, content] : after)
    EXPECT_TRUE(before.count(name)) << name << " was left behind (" << content.size() << " bytes)";
}

/// A run that failed (exit code 1) saying each of `messages`, leaving `dir` as it was `before`.
void expectFailedAndUnchanged(const test::CommandResult& r, const std::string& dir,
                              const std::map<std::string, std::string>& before,
                              const std::vector<std::string>& messages) {
  for (const std::string& m : messages) EXPECT_TRUE(test::failedNaming(r, m));
  expectUnchanged(before, dir);
}

/// Mounts made after this stay private to this test process (and its children) and vanish
/// with it. Empty on success, else why not.
std::string enterPrivateMountNamespace() {
  static const std::string why = [] {
    if (::unshare(CLONE_NEWNS) != 0)
      return std::string("unshare(CLONE_NEWNS): ") + std::strerror(errno);
    if (::mount("none", "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0)
      return std::string("making / private: ") + std::strerror(errno);
    return std::string();
  }();
  return why;
}

/// A tmpfs of `kib` KiB on `dir`; empty on success, else why not.
std::string mountSmallDisk(const std::string& dir, size_t kib) {
  if (std::string why = enterPrivateMountNamespace(); !why.empty()) return why;
  const std::string options = "size=" + std::to_string(kib) + "k";
  if (::mount("tmpfs", dir.c_str(), "tmpfs", 0, options.c_str()) != 0)
    return "mount -t tmpfs -o " + options + ": " + std::strerror(errno);
  return {};
}

/// Creates `dir` as a tmpfs of `kib` KiB, or skips (or fails, see SLAMDUNK_SKIP) the test where
/// mounting is not allowed.
#define REQUIRE_SMALL_DISK(dir, kib)                                   \
  fs::create_directories(dir);                                         \
  if (const std::string why = mountSmallDisk(dir, kib); !why.empty())  \
  SLAMDUNK_SKIP("this machine does not allow mounting a small tmpfs (" \
                << why << "); the file size limit test covers the same code")

/// Makes `dir` unwritable for the apps; empty on success, else why not.
std::string makeReadOnly(const std::string& dir) {
  if (::geteuid() != 0) {
    if (::chmod(dir.c_str(), 0555) != 0) return std::string("chmod: ") + std::strerror(errno);
    return {};
  }
  if (std::string why = enterPrivateMountNamespace(); !why.empty()) return why;
  if (::mount(dir.c_str(), dir.c_str(), nullptr, MS_BIND, nullptr) != 0 ||
      ::mount(nullptr, dir.c_str(), nullptr, MS_REMOUNT | MS_BIND | MS_RDONLY, nullptr) != 0)
    return std::string("read-only bind mount: ") + std::strerror(errno);
  return {};
}

/// The command run with a file size limit of `kib` KiB (SIGXFSZ ignored: writes fail instead).
/// In double quotes: the command's own arguments are single-quoted.
std::string withFileSizeLimit(size_t kib, const std::string& command) {
  return "bash -c \"trap '' XFSZ; ulimit -f " + std::to_string(kib) + "; exec " + command + "\"";
}

// ------------------------------------------------------------------ the apps' command lines

const std::vector<std::string> kRawlogOutputs = {"trajectory.txt", "trajectory_keyframes.txt",
                                                 "frames.csv",     "m.map",
                                                 "dense.ply",      "dense.pcd",
                                                 "dense.ot",       "dense.bt",
                                                 "m.png",          "m.3Dscene",
                                                 "m.simplemap"};

/// slamdunk-rawlog on 40 frames of the sweep with every output into `dir`.
std::string rawlogCommand(const std::string& rawlog, const std::string& dir) {
  return test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " --max-frames 40 -q" +
         " --trajectory " + q(dir + "/trajectory.txt") + " --frame-log " + q(dir + "/frames.csv") +
         " --save-map " + q(dir + "/m.map") + " --dense " + q(dir + "/dense") + " --render " +
         q(dir + "/m.png") + " --simplemap " + q(dir + "/m.simplemap");
}

const std::vector<std::string> kLiveOutputs = {"trajectory.txt", "trajectory_keyframes.txt",
                                               "frames.csv", "run.map", "rec.rawlog"};

/// slamdunk-live replaying 40 frames of the sweep, every output into `dir`.
std::string liveCommand(const std::string& rawlog, const std::string& dir,
                        const std::string& iniDir) {
  const std::string ini = iniDir + "/live.ini";
  std::ofstream(ini) << "[slamdunk-live]\nsource = REPLAY\nqueue_capacity = 100\n"
                        "[REPLAY]\ndriver = replay\nrawlog = "
                     << rawlog << "\n";
  return test::toolPath("slamdunk-live") + " --config " + q(ini) + " --max-frames 40 -q" +
         " --trajectory " + q(dir + "/trajectory.txt") + " --frame-log " + q(dir + "/frames.csv") +
         " --map " + q(dir + "/run.map") + " --record " + q(dir + "/rec.rawlog");
}

}  // namespace

// ------------------------------------------------------------------ read-only folder

TEST(HostileOutputs, ReadOnlyOutputFolderIsNamedAtOnceAndKeepsItsFiles) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string base = test::scratchDir("HostileOut_ReadOnly");
  const std::string dir = base + "/out";
  const auto rawlogBefore = writeEarlierFiles(dir, kRawlogOutputs);
  if (const std::string why = makeReadOnly(dir); !why.empty())
    SLAMDUNK_SKIP("cannot make a read-only folder here (" << why << ")");

  const auto t0 = std::chrono::steady_clock::now();
  const std::string notWritable = "output folder '" + dir + "' is not writable";
  expectFailedAndUnchanged(test::runCommand(rawlogCommand(rawlog, dir)), dir, rawlogBefore,
                           {notWritable});
  // Checked before the run, not after minutes of work.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 20);

  expectFailedAndUnchanged(test::runCommand(liveCommand(rawlog, dir, base)), dir, rawlogBefore,
                           {notWritable});
}

// ------------------------------------------------------------------ slamdunk-rawlog

// A disk with room for the small outputs but not for the map: nothing is replaced.
TEST(HostileOutputs, OfflineFullDiskReplacesNothing) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("HostileOut_OfflineDisk") + "/disk";
  // 11 earlier files take 44 KiB (a page each); 64 KiB more: room for the trajectories and the
  // frame log, not for the map (about 150 KB here) nor the dense cloud (about 1 MB).
  REQUIRE_SMALL_DISK(dir, 44 + 64);
  const auto before = writeEarlierFiles(dir, kRawlogOutputs);
  const auto r = test::runCommand(rawlogCommand(rawlog, dir));
  expectFailedAndUnchanged(
      r, dir, before, {"error: cannot write '" + dir + "/m.map'", "KiB free in '" + dir + "'"});
}

TEST(HostileOutputs, OfflineFileSizeLimitReplacesNothing) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("HostileOut_OfflineLimit");
  const auto before = writeEarlierFiles(dir, kRawlogOutputs);
  const auto r = test::runCommand(withFileSizeLimit(64, rawlogCommand(rawlog, dir)));
  expectFailedAndUnchanged(
      r, dir, before,
      {"error: cannot write '" + dir + "/m.map'", "file size limit (ulimit -f) 64 KiB"});
}

// The last kilobyte of a compressed map fails to reach the disk: zlib reports that when the file
// is closed, which MRPT's CFileGZOutputStream::close() ignores, so the short map used to replace
// the user's as if it were complete. Now the gzip trailer is checked.
TEST(HostileOutputs, MapCutShortInItsLastKilobyteIsAnError) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("HostileOut_MapLastBytes");
  const std::string reference = dir + "/reference";
  fs::create_directories(reference);
  const std::string args = " --max-frames 40 -q --save-map ";
  const auto full =
      test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " --trajectory " +
                       q(reference + "/t.txt") + args + q(reference + "/m.map"));
  ASSERT_EQ(full.exitCode, 0) << full.output;
  const size_t mapBytes = fs::file_size(reference + "/m.map");
  ASSERT_GT(mapBytes, 4096u);
  const std::string out = dir + "/out";
  const auto before = writeEarlierFiles(out, {"t.txt", "t_keyframes.txt", "m.map"});
  // The same deterministic run, limited to the map's size rounded down to whole KiB.
  const size_t limitKiB = (mapBytes - 1) / 1024;
  const auto r = test::runCommand(withFileSizeLimit(
      limitKiB, test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " --trajectory " +
                    q(out + "/t.txt") + args + q(out + "/m.map")));
  expectFailedAndUnchanged(r, out, before,
                           {"cannot write '" + out + "/m.map'", "was not written completely"});
}

// ------------------------------------------------------------------ slamdunk-live

namespace {
/// After a live session whose map and recording could not be written: those two kept their
/// earlier version and are named, the small outputs were written and are complete.
void expectLiveWroteWhatFitted(const test::CommandResult& r, const std::string& dir,
                               const std::map<std::string, std::string>& before,
                               const std::string& why) {
  EXPECT_EQ(r.exitCode, 1) << r.output;
  for (const char* failed : {"run.map", "rec.rawlog"}) {
    EXPECT_NE(r.output.find("error: cannot write '" + dir + "/" + failed + "'"), std::string::npos)
        << failed << "\n"
        << r.output;
    EXPECT_EQ(readFile(dir + "/" + failed), before.at(failed)) << failed;
  }
  EXPECT_NE(r.output.find(why), std::string::npos) << r.output;
  const Trajectory traj = readTumTrajectory(dir + "/trajectory.txt");
  EXPECT_GE(traj.size(), 35u);
  EXPECT_EQ(readTumTrajectory(dir + "/trajectory_keyframes.txt").size(), 1u);
  std::ifstream log(dir + "/frames.csv");
  size_t lines = 0;
  for (std::string line; std::getline(log, line);) ++lines;
  EXPECT_EQ(lines, 41u);  // header + one per frame
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  EXPECT_EQ(names, std::set<std::string>(kLiveOutputs.begin(), kLiveOutputs.end()))
      << "temporary files were left behind";
}
}  // namespace

TEST(HostileOutputs, LiveFullDiskWritesWhatFitsAndKeepsTheRest) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string base = test::scratchDir("HostileOut_LiveDisk");
  const std::string dir = base + "/disk";
  // 5 earlier files (20 KiB) and 64 KiB: the recording (about 1 MB a frame) fills the disk
  // early in the session; it must give that space back for the trajectory.
  REQUIRE_SMALL_DISK(dir, 20 + 64);
  const auto before = writeEarlierFiles(dir, kLiveOutputs);
  const auto r = test::runCommand(liveCommand(rawlog, dir, base));
  expectLiveWroteWhatFitted(r, dir, before, "KiB free in '" + dir + "'");
}

TEST(HostileOutputs, LiveFileSizeLimitWritesWhatFitsAndKeepsTheRest) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string base = test::scratchDir("HostileOut_LiveLimit");
  const std::string dir = base + "/out";
  const auto before = writeEarlierFiles(dir, kLiveOutputs);
  const auto r = test::runCommand(withFileSizeLimit(64, liveCommand(rawlog, dir, base)));
  expectLiveWroteWhatFitted(r, dir, before, "file size limit (ulimit -f) 64 KiB");
}
