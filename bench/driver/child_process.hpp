#pragma once
// A child process started with posix_spawn: an argv, extra environment, an fd passed in as
// fd 3, stdout/stderr into a log file. The destructor stops it (SIGTERM, then SIGKILL).

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

#include "pmu/transport/unique_fd.hpp"

namespace pmu::bench {

using SteadyTime = std::chrono::steady_clock::time_point;

class ChildProcess {
 public:
  // Throws std::runtime_error when the spawn fails. `fd3` (may be empty) becomes the
  // child's fd 3; the parent's copy is closed.
  ChildProcess(std::vector<std::string> argv, std::vector<std::string> extra_env, transport::UniqueFd fd3,
               const std::string& log_file);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const noexcept { return pid_; }
  // steady_clock time just before posix_spawn.
  SteadyTime spawned_at() const noexcept { return spawned_at_; }
  bool running();
  // SIGTERM and wait; SIGKILL after `grace`. Returns the exit status (-signal if killed).
  int stop(std::chrono::milliseconds grace = std::chrono::milliseconds(3000));
  // Waits for the child to exit on its own; -1 on timeout.
  int wait(std::chrono::milliseconds timeout);

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int status_ = 0;
  SteadyTime spawned_at_;
};

// The last `lines` lines of a log file, for error messages.
std::string tail(const std::string& file, int lines = 5);

}  // namespace pmu::bench
