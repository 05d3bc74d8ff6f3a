#pragma once
// Writes an output file so the user's existing file is never lost to a failed run: everything
// goes to a temporary file beside the target, renamed over it only by commit().

#include <string>

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
  /// Replaces the target folder (and everything in it) by the temporary one.
  void commit();

 private:
  std::string target_;
  std::string temp_;
  bool committed_ = false;
};

}  // namespace slamdunk
