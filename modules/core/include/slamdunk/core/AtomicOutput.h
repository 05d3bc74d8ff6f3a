#pragma once
// Writes an output file so the user's existing file is never lost to a failed run: everything
// goes to a temporary file beside the target, renamed over it only by commit().

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mrpt::serialization {
class CSerializable;
}

namespace slamdunk {

class AtomicOutput {
 public:
  explicit AtomicOutput(std::string targetPath);
  ~AtomicOutput();  ///< Removes the temporary file unless commit() succeeded.
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  /// Where to write now (same folder as the target, so the rename is atomic).
  const std::string& tempPath() const { return temp_; }
  const std::string& targetPath() const { return target_; }
  /// Renames the temporary file over the target. Throws std::runtime_error on failure.
  void commit();

 private:
  std::string target_;
  std::string temp_;
  bool committed_ = false;
};

/// The same for a folder (e.g. a rawlog's "<name>_Images"): filled under a temporary name beside
/// the target and swapped in by commit(); removed if never committed.
class AtomicOutputFolder {
 public:
  explicit AtomicOutputFolder(std::string targetPath);
  ~AtomicOutputFolder();
  AtomicOutputFolder(const AtomicOutputFolder&) = delete;
  AtomicOutputFolder& operator=(const AtomicOutputFolder&) = delete;

  const std::string& tempPath() const { return temp_; }
  /// Replaces the target folder (and everything in it) by the temporary one; atomically where
  /// the filesystem can swap two folders (Linux: ext4, xfs, btrfs, tmpfs).
  void commit();

 private:
  std::string target_;
  std::string temp_;
  bool committed_ = false;
};

/// The outputs of one run, replaced together. Each is written under a temporary name beside its
/// target (stage()); commit() renames them all over their targets, and only once every one was
/// written: a run that fails on its last output (a full disk, say) leaves every earlier file of
/// the user's as it was. Whatever was staged and not committed is removed.
class StagedOutputs {
 public:
  StagedOutputs() = default;
  ~StagedOutputs();
  StagedOutputs(const StagedOutputs&) = delete;
  StagedOutputs& operator=(const StagedOutputs&) = delete;

  /// Registers `target` and returns where to write it now (same folder, hidden name).
  std::string stage(const std::string& target);
  /// For a writer that appends extensions to a prefix (PREFIX.ply, PREFIX.pcd, ...): registers
  /// prefix + each extension and returns the staged prefix to hand to the writer.
  std::string stagePrefix(const std::string& prefix, const std::vector<std::string>& extensions);
  /// Renames every staged file over its target. Throws std::runtime_error naming a staged
  /// output that is missing (never written) or cannot be renamed.
  void commit();

 private:
  std::vector<std::pair<std::string, std::string>> files_;  ///< (target, staged)
  bool committed_ = false;
};

/// A path a tool was given, and how the user gave it ("--gt", "IN.rawlog"); empty = not given.
struct NamedPath {
  std::string role;
  std::string path;
};

/// Throws std::invalid_argument naming both when an output is the same file as an input (`-t
/// GT.txt --gt GT.txt` would replace the user's ground truth with the run's trajectory) or as
/// another output (one would replace the other). Same file: one existing file under two names
/// (links included), or the same absolute path once symbolic links are resolved. Checked before
/// a run, so nothing is read that is about to be replaced.
void rejectPathClashes(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

/// Throws std::runtime_error unless the folder of `target` exists and this process may create
/// files in it (a read-only mount, a folder without write permission): checked before a run
/// that may take minutes rather than after it.
void requireWritableFolder(const std::string& target);

/// A gzip file ends with the length of its uncompressed data (mod 2^32). When the last write of
/// a compressed output fails (a full disk), zlib's close reports it but MRPT's
/// CFileGZOutputStream::close() does not: the file just ends early. Throws std::runtime_error
/// naming `target` unless the gzip file at `path` ends with the length `uncompressedBytes`
/// (CFileGZOutputStream::getPosition() before close()).
void requireCompleteGzip(const std::string& path, uint64_t uncompressedBytes,
                         const std::string& target);

/// Writes `object` as MRPT's gzip-compressed archive (what its `.gridmap`, `.simplemap` and
/// `.3Dscene` readers take) to `path` through an AtomicOutput, checked by requireCompleteGzip().
/// Throws std::runtime_error naming `path` when it cannot be opened or is cut short.
void writeGzArchive(const std::string& path, const mrpt::serialization::CSerializable& object,
                    int compressionLevel = 1);

/// Why writing `target` may have failed, as far as can be told afterwards: the free space left
/// on its filesystem, and the process's file size limit (ulimit -f) if it has one.
std::string writeFailureHint(const std::string& target);

/// `text` with every occurrence of the staged name replaced by the target's, so that messages
/// name the files the user asked for.
std::string withTargetName(std::string text, const std::string& staged, const std::string& target);

/// The message for a failed write of `target`: "cannot write 'target': <why> (<hint>)", where
/// the (hidden) name it was staged under, if given, reads as the target's, and the hint is
/// writeFailureHint()'s. `why` may be an MRPT exception text (reduced to one line).
std::string writeErrorMessage(const std::string& target, const std::string& why,
                              const std::string& stagedAs = {});

}  // namespace slamdunk
