#pragma once
// Some MRPT drivers print progress to stdout while loading and opening; the app keeps stdout
// for its summary (--json must stay parseable), so that chatter is sent to stderr meanwhile.

#include <unistd.h>

#include <cstdio>
#include <iostream>

namespace slamdunk::live {

class StdoutToStderr {
 public:
  StdoutToStderr() {
    std::cout.flush();
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    if (saved_ >= 0) dup2(STDERR_FILENO, STDOUT_FILENO);
  }
  ~StdoutToStderr() {
    std::cout.flush();
    std::fflush(stdout);
    if (saved_ >= 0) {
      dup2(saved_, STDOUT_FILENO);
      close(saved_);
    }
  }
  StdoutToStderr(const StdoutToStderr&) = delete;
  StdoutToStderr& operator=(const StdoutToStderr&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace slamdunk::live
