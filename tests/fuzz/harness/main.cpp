// fuzz-readers: a seeded mutation fuzzer for every reader of outside data (rawlogs, maps, INI
// files, TUM lists, trajectories and depth PNGs). Each input runs in-process; an accepted input
// goes on to what the apps do with it, a rejected one must raise a std::exception whose message
// names the file. Crashes, hangs, sanitizer reports, out-of-memory and unclean rejections are
// failures: the input is saved for --replay.

#include "Targets.h"

#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace slamdunk::fuzz;

#if defined(__SANITIZE_ADDRESS__)
#define FUZZ_WITH_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FUZZ_WITH_ASAN 1
#endif
#endif

#ifdef FUZZ_WITH_ASAN
// AddressSanitizer reserves terabytes of address space, so no RLIMIT_AS caps what MRPT's
// deserializers take on a corrupt length field (rawlogMrptPrecheck): a single allocation over
// the precheck's limit (kMrptPrecheckMiB) ends its child at once instead of zero-filling
// gigabytes first, which took most of the rawlog target's time. ASAN_OPTIONS may still set it
// otherwise.
extern "C" const char* __asan_default_options() { return "max_allocation_size_mb=256"; }
#endif

// Sanitizer runtimes call this before they end the process on a report (weak: absent otherwise).
extern "C" void __sanitizer_set_death_callback(void (*callback)(void)) __attribute__((weak));

namespace {

// ------------------------------------------------------------------ the input being run
// Read by signal handlers: plain data set before each input, saved with async-signal-safe calls.
const uint8_t* g_data = nullptr;
size_t g_size = 0;
char g_savePath[4096] = "";
char g_label[256] = "";
unsigned g_timeoutSeconds = 30;

void writeStderr(const char* s) {
  if (write(STDERR_FILENO, s, std::strlen(s)) < 0) return;
}

void saveCurrentInput() {
  if (!g_data || !g_savePath[0]) return;
  const int fd = open(g_savePath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return;
  size_t done = 0;
  while (done < g_size) {
    const ssize_t n = write(fd, g_data + done, g_size - done);
    if (n <= 0) break;
    done += size_t(n);
  }
  close(fd);
}

void reportAndSave(const char* what) {
  writeStderr("\nfuzz-readers: ");
  writeStderr(what);
  writeStderr(" on ");
  writeStderr(g_label);
  writeStderr("; input saved as ");
  writeStderr(g_savePath);
  writeStderr("\n");
  saveCurrentInput();
}

void onFatalSignal(int sig) {
  reportAndSave(sig == SIGALRM ? "TIMEOUT (hang)" : strsignal(sig));
  if (sig == SIGALRM) _exit(3);
  signal(sig, SIG_DFL);  // default action: the exit status shows the signal
  raise(sig);
}

void onSanitizerDeath() { reportAndSave("sanitizer report"); }

void installHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onFatalSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  sigaction(SIGALRM, &sa, nullptr);
  sigaction(SIGABRT, &sa, nullptr);
#ifndef FUZZ_WITH_ASAN
  // With AddressSanitizer these stay with its own handler, which reports and then calls
  // onSanitizerDeath.
  for (int s : {SIGSEGV, SIGBUS, SIGFPE, SIGILL}) sigaction(s, &sa, nullptr);
#endif
  if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(onSanitizerDeath);
}

// ------------------------------------------------------------------ memory

bool looksLikeOutOfMemory(const std::string& msg) {
  return msg.find("bad_alloc") != std::string::npos ||
         msg.find("Failed to allocate") != std::string::npos ||
         msg.find("Insufficient memory") != std::string::npos ||
         msg.find("bad array new length") != std::string::npos;
}

// ------------------------------------------------------------------ running inputs

struct Seed {
  std::string name;
  Bytes raw;    ///< as stored
  Bytes plain;  ///< inflated for gz-compressed targets, else = raw
};

enum class Verdict { Accepted, Rejected, Failure };

struct Result {
  Verdict verdict = Verdict::Accepted;
  std::string message;
};

struct Options {
  std::string crashesDir;
  long maxRssMiB = 1536;
};

uint64_t fnv1a(const Bytes& b) {
  uint64_t h = 1469598103934665603ULL;
  for (uint8_t c : b) h = (h ^ c) * 1099511628211ULL;
  return h;
}

Result runOne(const Target& t, const Bytes& input, const std::string& scratch, RunStats& stats,
              const Options& opt) {
  g_data = input.data();
  g_size = input.size();
  RunContext ctx{scratch, fnv1a(input)};
  const std::string expected = t.expectedName(scratch);
  Result r;
  resetPeakRss();
  alarm(g_timeoutSeconds);
  try {
    t.run(input, ctx, stats);
  } catch (const std::exception& e) {
    r.message = e.what();
    if (isUseFailure(e)) {
      r.verdict = Verdict::Failure;
    } else if (looksLikeOutOfMemory(r.message)) {
      r.verdict = Verdict::Failure;
      r.message = "out of memory (a size read from the input was not validated): " + r.message;
    } else if (r.message.find(expected) == std::string::npos) {
      r.verdict = Verdict::Failure;
      r.message = "the error does not name '" + expected + "': " + r.message;
    } else if (r.message.size() < expected.size() + 8) {
      r.verdict = Verdict::Failure;
      r.message = "the error does not say what is wrong: " + r.message;
    } else {
      r.verdict = Verdict::Rejected;
    }
  } catch (...) {
    r.verdict = Verdict::Failure;
    r.message = "an exception that is not a std::exception escaped";
  }
  alarm(0);
  const long peak = peakRssMiB();
  if (peak > opt.maxRssMiB && r.verdict != Verdict::Failure) {
    r.verdict = Verdict::Failure;
    r.message = "used " + std::to_string(peak) + " MiB of memory (limit " +
                std::to_string(opt.maxRssMiB) + ")";
  }
  return r;
}

/// runOne in a child process: a crash, hang or sanitizer abort then ends only that input, is
/// recorded as a failure, and the run goes on (--fork; for surveys of many failing inputs).
Result runForked(const Target& t, const Bytes& input, const std::string& scratch, RunStats& stats,
                 const Options& opt) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe() failed");
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork() failed");
  if (pid == 0) {
    close(fds[0]);
    RunStats childStats;
    const Result r = runOne(t, input, scratch, childStats, opt);
    std::string msg = char('0' + int(r.verdict)) + std::to_string(childStats.framesAccepted) + " " +
                      std::to_string(childStats.framesRejected) + " " +
                      std::to_string(childStats.useErrors) + "\n" + r.message;
    if (write(fds[1], msg.data(), msg.size()) < 0) _exit(4);
    close(fds[1]);
    _exit(0);
  }
  close(fds[1]);
  std::string reply;
  char buf[4096];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) reply.append(buf, size_t(n));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  Result r;
  if (WIFSIGNALED(status) || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || reply.empty()) {
    r.verdict = Verdict::Failure;
    r.message = WIFSIGNALED(status)
                    ? std::string("crashed: ") + strsignal(WTERMSIG(status))
                    : "the child ended with status " + std::to_string(WEXITSTATUS(status)) +
                          " (3 = timeout, 1 = sanitizer report)";
    return r;
  }
  r.verdict = Verdict(reply[0] - '0');
  const size_t nl = reply.find('\n');
  std::istringstream figures(reply.substr(1, nl - 1));
  size_t a = 0, b = 0, c = 0;
  figures >> a >> b >> c;
  stats.framesAccepted += a;
  stats.framesRejected += b;
  stats.useErrors += c;
  r.message = reply.substr(nl + 1);
  return r;
}

std::vector<Seed> loadCorpus(const Target& t, const std::vector<std::string>& dirs) {
  std::vector<Seed> seeds;
  for (const std::string& dir : dirs) {
    if (!fs::is_directory(dir)) throw std::runtime_error("corpus folder '" + dir + "' not found");
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && e.path().filename().string()[0] != '.' &&
          e.path().extension() != ".md")
        files.push_back(e.path());
    std::sort(files.begin(), files.end());  // directory order is not deterministic
    for (const fs::path& p : files) {
      Seed s{p.string(), readFileBytes(p.string()), {}};
      s.plain = t.gzipCorpus ? inflateFile(p.string()) : s.raw;
      seeds.push_back(std::move(s));
    }
  }
  return seeds;
}

std::string makeScratchDir(const std::string& target) {
  const fs::path base = fs::temp_directory_path();
  std::string tmpl = (base / ("fuzz-readers-" + target + "-XXXXXX")).string();
  if (!mkdtemp(tmpl.data()))
    throw std::runtime_error("cannot create a scratch folder in " + base.string());
  return tmpl;
}

const char* kDescription =
    "Seeded mutation fuzzing of the readers of outside data. TARGET is one of: rawlog "
    "(RawlogReader "
    "+ the pipeline on each observation), map (CKeyframeGraphMap::loadFromFile + render and "
    "relocalization), ini (pipeline, camera, live and map render INI readers), tum-list (TUM "
    "folder lists through tum2rawlog), tum-trajectory (readTumTrajectory + ATE/RPE), depth-png "
    "(a TUM depth PNG through tum2rawlog). Inputs are the corpus files unchanged, then mutations "
    "of them (bit flips, byte insert/delete/duplicate, truncation, splicing, interesting values "
    "as bytes and as text, line edits) and structure-aware ones (hostile observations, maps, "
    "PNGs). Deterministic for a seed. Exit status 0 when every input was accepted or rejected "
    "with an error naming the file, 1 otherwise (failing inputs are saved in --crashes).";

}  // namespace

int main(int argc, char** argv) {
  try {
    TCLAP::CmdLine cmd(kDescription, ' ', "1.0");
    TCLAP::UnlabeledValueArg<std::string> argTarget("target", "reader to fuzz", false, "", "TARGET",
                                                    cmd);
    TCLAP::ValueArg<size_t> argRuns("n", "runs", "mutated inputs to run (default 1000)", false,
                                    1000, "N", cmd);
    TCLAP::ValueArg<uint64_t> argSeed("s", "seed", "random seed (default 1)", false, 1, "S", cmd);
    TCLAP::MultiArg<std::string> argCorpus("c", "corpus", "seed corpus folder (repeatable)", false,
                                           "DIR", cmd);
    TCLAP::ValueArg<std::string> argCrashes("", "crashes",
                                            "folder for failing inputs (default ./fuzz-crashes)",
                                            false, "fuzz-crashes", "DIR", cmd);
    TCLAP::ValueArg<unsigned> argTimeout(
        "", "timeout", "seconds per input before it counts as a hang (default 10)", false, 10,
        "SEC", cmd);
    TCLAP::ValueArg<long> argMaxRss(
        "", "max-rss-mb", "peak memory per input before it counts as a failure (default 1536)",
        false, 1536, "MB", cmd);
    TCLAP::ValueArg<std::string> argReplay("", "replay", "run one saved input and report", false,
                                           "", "FILE", cmd);
    TCLAP::ValueArg<std::string> argMakeCorpus(
        "", "make-corpus", "write the generated seed files under DIR/<target>/ and exit", false, "",
        "DIR", cmd);
    TCLAP::SwitchArg argVerbose("v", "verbose", "print every rejection message", cmd);
    TCLAP::SwitchArg argFork("", "fork",
                             "run each input in a child process: a crash is recorded and the "
                             "run goes on (slower; for surveys)",
                             cmd);
    cmd.parse(argc, argv);

    if (argMakeCorpus.isSet()) {
      makeCorpus(argMakeCorpus.getValue());
      std::printf("seed corpus written under %s\n", argMakeCorpus.getValue().c_str());
      return 0;
    }
    const Target* target = findTarget(argTarget.getValue());
    if (!target) {
      std::string names;
      for (const Target& t : allTargets()) names += " " + t.name;
      throw std::runtime_error("unknown or missing TARGET '" + argTarget.getValue() +
                               "' (one of:" + names + ")");
    }
    g_timeoutSeconds = std::max(1u, argTimeout.getValue());
    Options opt;
    opt.crashesDir = argCrashes.getValue();
    opt.maxRssMiB = argMaxRss.getValue();
    installHandlers();
    const std::string scratch = makeScratchDir(target->name);
    RunStats stats;

    if (argReplay.isSet()) {
      const Bytes input = readFileBytes(argReplay.getValue());
      std::snprintf(g_label, sizeof g_label, "replay of %s", argReplay.getValue().c_str());
      if (target->mrptPrecheck) {
        const std::string why = target->mrptPrecheck(input, RunContext{scratch, 0});
        if (!why.empty()) std::printf("%s: %s\n", argReplay.getValue().c_str(), why.c_str());
      }
      const Result r = runOne(*target, input, scratch, stats, opt);
      fs::remove_all(scratch);
      const char* v = r.verdict == Verdict::Accepted   ? "accepted"
                      : r.verdict == Verdict::Rejected ? "rejected"
                                                       : "FAILURE";
      std::printf("%s: %s%s%s\n", argReplay.getValue().c_str(), v, r.message.empty() ? "" : ": ",
                  r.message.c_str());
      return r.verdict == Verdict::Failure ? 1 : 0;
    }

    const std::vector<Seed> seeds = loadCorpus(*target, argCorpus.getValue());
    if (seeds.empty() && !target->generate)
      throw std::runtime_error("target '" + target->name + "' needs a seed corpus (--corpus DIR)");
    fs::create_directories(opt.crashesDir);

    Rng rng(argSeed.getValue());
    size_t accepted = 0, rejected = 0, failures = 0, seedsRejected = 0, mrptUnsafe = 0;
    const size_t runs = argRuns.getValue();
    const auto start = std::chrono::steady_clock::now();
    // The seeds unchanged first: each must be accepted (a check on the harness and corpus).
    for (size_t i = 0; i < seeds.size() + runs; ++i) {
      const bool isSeed = i < seeds.size();
      Bytes input;
      if (isSeed) {
        input = seeds[i].plain;
      } else if (target->generate && (seeds.empty() || rng.chance(25))) {
        input = target->generate(rng);
        if (rng.chance(50) && !seeds.empty())
          mutate(input, seeds[rng.below(seeds.size())].plain, target->kind, rng);
        else if (rng.chance(50))
          mutate(input, {}, target->kind, rng);
      } else {
        const Seed& s = seeds[rng.below(seeds.size())];
        // Now and then the stored (compressed) bytes: exercises the gz layer's own errors.
        input = target->gzipCorpus && rng.chance(6) ? s.raw : s.plain;
        mutate(input, seeds[rng.below(seeds.size())].plain, target->kind, rng);
      }
      if (target->pngCrcFix && !isSeed && rng.chance(80)) fixPngCrcs(input);

      const std::string saveName =
          isSeed ? target->name + "-seed-" + fs::path(seeds[i].name).filename().string()
                 : target->name + "-s" + std::to_string(argSeed.getValue()) + "-" +
                       std::to_string(i - seeds.size()) + "." + target->extension;
      std::snprintf(g_savePath, sizeof g_savePath, "%s",
                    (fs::path(opt.crashesDir) / saveName).string().c_str());
      std::snprintf(g_label, sizeof g_label, "%s", saveName.c_str());

      g_data = input.data();
      g_size = input.size();
      if (target->mrptPrecheck) {
        const std::string why = target->mrptPrecheck(input, RunContext{scratch, 0});
        if (!why.empty()) {
          // MRPT's own deserializer fails on it: saved apart, not a failure of the project.
          ++mrptUnsafe;
          const fs::path dir = fs::path(opt.crashesDir) / "mrpt-unsafe";
          fs::create_directories(dir);
          writeFileBytes((dir / saveName).string(), input);
          if (argVerbose.getValue())
            std::fprintf(stderr, "%s: %s\n", saveName.c_str(), why.c_str());
          continue;
        }
      }
      const Result r = argFork.getValue() ? runForked(*target, input, scratch, stats, opt)
                                          : runOne(*target, input, scratch, stats, opt);
      if (r.verdict == Verdict::Accepted) {
        ++accepted;
      } else if (r.verdict == Verdict::Rejected) {
        ++rejected;
        if (isSeed) {
          ++seedsRejected;
          std::fprintf(stderr, "fuzz-readers: seed %s was rejected: %s\n", seeds[i].name.c_str(),
                       r.message.c_str());
        }
        if (argVerbose.getValue()) std::fprintf(stderr, "rejected: %s\n", r.message.c_str());
      } else {
        ++failures;
        saveCurrentInput();
        std::fprintf(stderr, "fuzz-readers: FAILURE on %s: %s\n  input saved as %s\n", g_label,
                     r.message.c_str(), g_savePath);
      }
    }
    g_data = nullptr;
    fs::remove_all(scratch);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const size_t total = seeds.size() + runs;
    std::printf(
        "fuzz-readers %s: %zu inputs (%zu seeds + %zu mutated, seed %llu) in %.1f s (%.0f/s): "
        "%zu accepted, %zu rejected with an error naming the file, %zu failures; frames usable "
        "%zu, unusable %zu; later-stage errors %zu\n",
        target->name.c_str(), total, seeds.size(), runs,
        static_cast<unsigned long long>(argSeed.getValue()), seconds, total / seconds, accepted,
        rejected, failures, stats.framesAccepted, stats.framesRejected, stats.useErrors);
    if (mrptUnsafe)
      std::printf(
          "fuzz-readers %s: %zu input(s) not run: MRPT's own deserializer crashes, hangs or "
          "allocates over 256 MiB on them (saved in %s/mrpt-unsafe)\n",
          target->name.c_str(), mrptUnsafe, opt.crashesDir.c_str());
    if (seedsRejected)
      std::printf("fuzz-readers %s: %zu seed(s) rejected: the corpus or the harness is stale\n",
                  target->name.c_str(), seedsRejected);
    return failures == 0 && seedsRejected == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz-readers: %s\n", e.what());
    return 1;
  }
}
