#pragma once
// The readers of outside data the fuzz driver exercises, one Target each: how an input is laid
// out on disk, which reader runs on it, and what the apps do next with what it accepted.

#include "Mutator.h"

#include <exception>
#include <functional>
#include <string>
#include <vector>

namespace slamdunk::fuzz {

/// Per-target figures beyond accepted/rejected (e.g. frames an app would report as unusable).
struct RunStats {
  size_t framesAccepted = 0;  ///< observations turned into frames
  size_t framesRejected = 0;  ///< observations the app reports as unusable (lost frame)
  size_t useErrors = 0;       ///< accepted data a later stage refused with an exception
};

/// Peak resident memory since the last reset, MiB (Linux: VmHWM, reset through clear_refs).
long peakRssMiB();
void resetPeakRss();

/// Where and how one input runs. `dir` is a scratch folder owned by the driver.
struct RunContext {
  std::string dir;
  /// Derived from the input's bytes (so a replay behaves the same): picks variants such as the
  /// camera calibration or external images.
  uint64_t variant = 0;
};

struct Target {
  std::string name;
  std::string extension;  ///< of saved inputs (crashes, corpus)
  InputKind kind = InputKind::Binary;
  bool gzipCorpus = false;  ///< corpus files are gz-compressed MRPT archives: mutate them inflated
  bool pngCrcFix = false;   ///< recompute PNG chunk CRCs after mutating
  /// Structure-aware generator (valid framing, hostile values); may be empty.
  std::function<Bytes(Rng&)> generate;
  /// The path a rejection message must name (file or folder) for inputs run in `dir`.
  std::function<std::string(const std::string& dir)> expectedName;
  /// Optional: reads the input with MRPT alone (no project code) in a child process and returns
  /// why MRPT itself cannot read it safely (crash, hang, gigabytes), or "" when it can. Such
  /// inputs are counted and saved apart: the project cannot reject them before MRPT reads them.
  std::function<std::string(const Bytes&, const RunContext&)> mrptPrecheck;
  /// Lays the input out under ctx.dir and runs the reader, then what the apps do with what it
  /// returned. Throws (std::exception) what the reader throws for a rejected input.
  std::function<void(const Bytes&, const RunContext&, RunStats&)> run;
};

/// Every target, in a fixed order: rawlog, map, ini, tum-list, tum-trajectory, depth-png.
const std::vector<Target>& allTargets();
const Target* findTarget(const std::string& name);
/// True for the errors a target raises when a later stage failed on data a reader accepted.
bool isUseFailure(const std::exception& e);

/// Writes the generated part of the seed corpus under dir/<target>/ (rawlogs, maps, PNGs, TUM
/// lists and trajectories); the INI seeds are the repository's own files (see tests/fuzz).
void makeCorpus(const std::string& dir);

Bytes readFileBytes(const std::string& path);
void writeFileBytes(const std::string& path, const Bytes& data);
/// The inflated content of a gz file (a plain file is returned as is).
Bytes inflateFile(const std::string& path);

}  // namespace slamdunk::fuzz
