#pragma once
// pmu::test_support: child processes for tests.
//
// Child: one program started with fork/execve, stopped and reaped when the Child goes out of
// scope (SIGTERM, then SIGKILL if it has not exited within `stop_grace`), so a failing
// assertion never leaves a pmu-service running; the child also gets SIGTERM if the test
// process dies first (PR_SET_PDEATHSIG; start children from the test's main thread).
// SIGTERM first: a Fast DDS participant killed outright leaves its shared-memory ports
// behind for later tests to wait on.
//
//   pmu::test::ChildOptions o;
//   o.stderr_path = "/tmp/x.log";
//   pmu::test::Child service({PMU_SERVICE_PATH, "--bus", "sim", "--domain", "37"}, o);
//   ...
//   const auto st = service.stop(3s);   // raw wait status, std::nullopt if it had to be killed
//
// run_capture: a shell command (sh -c, so `VAR=x prog 2>&1` works), its stdout and its exit
// status:
//
//   const auto r = pmu::test::run_capture(PMUCTL_PATH " list --json");
//   // r.status: 0..255 when it exited, -1 when a signal ended it; r.out: its stdout
#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace pmu::test {

struct ChildOptions {
  std::vector<std::string> env;                 // "NAME=value", added to (or replacing in) this process's environment
  std::string stdout_path;                      // empty: inherited
  std::string stderr_path;                      // empty: inherited; same as stdout_path: both into one file
  std::chrono::milliseconds stop_grace{10000};  // SIGTERM -> SIGKILL in the destructor
};

class Child {
 public:
  Child() = default;
  // argv[0] is the program's path (no PATH search). Throws std::runtime_error when it cannot
  // fork or open an output file; a program that cannot be executed exits with status 127.
  explicit Child(const std::vector<std::string>& argv, const ChildOptions& options = {});
  ~Child();
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  Child(Child&& other) noexcept;
  Child& operator=(Child&& other) noexcept;

  pid_t pid() const { return pid_; }
  // True while the process has not exited (reaps it, keeping its status, once it has).
  bool running();
  // Sends `sig`; false when the process is gone.
  bool signal(int sig);
  // Waits up to `timeout` for it to exit: its raw wait status (WIFEXITED, WEXITSTATUS...), or
  // std::nullopt when it is still running.
  std::optional<int> wait_for(std::chrono::milliseconds timeout);
  // SIGTERM, then waits up to `grace`; SIGKILL after that. The raw wait status, or
  // std::nullopt when SIGKILL was needed (or nothing was started).
  std::optional<int> stop(std::chrono::milliseconds grace);
  // The raw wait status once it has exited and been reaped.
  std::optional<int> status() const { return status_; }

 private:
  void reap_now_or_kill();
  pid_t pid_ = -1;
  std::optional<int> status_;
  std::chrono::milliseconds stop_grace_{10000};
};

struct RunResult {
  int status = -1;  // exit status 0..255, -1 when it did not exit normally (signal) or never ran
  std::string out;
};

// Runs `command` with /bin/sh and returns its stdout (with stderr too when merge_stderr).
RunResult run_capture(const std::string& command, bool merge_stderr = false);

}  // namespace pmu::test
