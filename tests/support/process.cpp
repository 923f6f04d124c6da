#include "process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace pmu::test {

namespace {

int open_output(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  return fd;
}

std::string env_name(const std::string& entry) { return entry.substr(0, entry.find('=')); }

}  // namespace

Child::Child(const std::vector<std::string>& argv, const ChildOptions& options) : stop_grace_(options.stop_grace) {
  if (argv.empty()) throw std::invalid_argument("Child: empty argv");
  // Everything the child needs is built before fork(): after it, in a process with threads
  // (Fast DDS's), only async-signal-safe calls are allowed.
  std::vector<std::string> env_strings;
  for (char** e = environ; e && *e; ++e) {
    const std::string entry(*e);
    bool replaced = false;
    for (const auto& o : options.env) replaced = replaced || env_name(o) == env_name(entry);
    if (!replaced) env_strings.push_back(entry);
  }
  for (const auto& o : options.env) env_strings.push_back(o);
  std::vector<char*> args, envp;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  int out_fd = -1, err_fd = -1;
  if (!options.stdout_path.empty()) out_fd = open_output(options.stdout_path);
  if (!options.stderr_path.empty())
    err_fd = options.stderr_path == options.stdout_path ? out_fd : open_output(options.stderr_path);

  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0) {
    // Dies with the test (SIGTERM when the forking thread ends: tests start children from
    // their main thread): a killed test must not leave a pmu-service on its domain, which
    // the kernel hands to the next test once the test's lock is gone.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);
    if (out_fd >= 0) ::dup2(out_fd, 1);  // dup2 clears O_CLOEXEC on the copy
    if (err_fd >= 0) ::dup2(err_fd, 2);
    ::execve(args[0], args.data(), envp.data());
    ::_exit(127);
  }
  const int fork_errno = errno;
  if (out_fd >= 0) ::close(out_fd);
  if (err_fd >= 0 && err_fd != out_fd) ::close(err_fd);
  if (pid_ < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(fork_errno));
}

Child::~Child() {
  if (pid_ > 0 && !status_) (void)stop(stop_grace_);
}

Child::Child(Child&& other) noexcept : pid_(other.pid_), status_(other.status_), stop_grace_(other.stop_grace_) {
  other.pid_ = -1;
  other.status_.reset();
}

Child& Child::operator=(Child&& other) noexcept {
  if (this != &other) {
    if (pid_ > 0 && !status_) (void)stop(stop_grace_);
    pid_ = other.pid_;
    status_ = other.status_;
    stop_grace_ = other.stop_grace_;
    other.pid_ = -1;
    other.status_.reset();
  }
  return *this;
}

bool Child::running() {
  if (pid_ <= 0 || status_) return false;
  int st = 0;
  const pid_t r = ::waitpid(pid_, &st, WNOHANG);
  if (r == pid_) {
    status_ = st;
    return false;
  }
  return r == 0;
}

bool Child::signal(int sig) { return running() && ::kill(pid_, sig) == 0; }

std::optional<int> Child::wait_for(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (running()) {
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return status_;
}

std::optional<int> Child::stop(std::chrono::milliseconds grace) {
  if (pid_ <= 0) return std::nullopt;
  if (status_) return status_;
  (void)signal(SIGTERM);
  if (auto st = wait_for(grace)) return st;
  reap_now_or_kill();
  return std::nullopt;
}

void Child::reap_now_or_kill() {
  ::kill(pid_, SIGKILL);
  int st = 0;
  while (::waitpid(pid_, &st, 0) < 0 && errno == EINTR) {
  }
  status_ = st;
}

RunResult run_capture(const std::string& command, bool merge_stderr) {
  RunResult r;
  FILE* p = ::popen((merge_stderr ? command + " 2>&1" : command).c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = ::pclose(p);
  r.status = st != -1 && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

}  // namespace pmu::test
