#pragma once
// A program started in the background by a test, its output in a log file; stopped (with
// everything it started) when the object goes.

#include <sys/types.h>

#include <string>
#include <vector>

namespace slamdunk::test {

class ChildProcess {
 public:
  /// Starts argv[0] (looked up on PATH) with `extraEnv` ("NAME=value") added to this process's
  /// environment; stdout and stderr go to `logFile`. started() tells whether it ran.
  ChildProcess(const std::vector<std::string>& argv, const std::vector<std::string>& extraEnv,
               const std::string& logFile);
  ~ChildProcess();  ///< stop()
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  /// Still running (not exited, not killed).
  bool alive();
  /// Waits up to `seconds` for it to exit; its exit code (128 + signal when killed), or -1 if
  /// it is still running.
  int wait(double seconds);
  /// SIGTERM to its process group, SIGKILL after 5 s.
  void stop();

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
  int exitCode_ = -1;
};

}  // namespace slamdunk::test
