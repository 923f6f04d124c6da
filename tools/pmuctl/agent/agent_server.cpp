#include "pmuctl/agent/agent_server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <new>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <thread>
#include <vector>

#include "pmuctl/agent/agent_request.hpp"
#include "pmuctl/agent/unix_socket.hpp"

namespace pmu::tools {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop = true; }

// The caller's standard streams, working directory and environment for the length of one
// call, and the agent's own back afterwards (also when the call throws).
class CallerScope {
 public:
  CallerScope(const AgentRequest& request, const std::vector<UniqueFd>& fds, std::string& error) {
    own_dir_ = UniqueFd(::open(".", O_RDONLY | O_DIRECTORY | O_CLOEXEC));
    if (::chdir(request.directory.c_str()) != 0) {
      error = "cannot enter the caller's directory " + request.directory + ": " + std::strerror(errno);
      return;
    }
    for (const char* name : kAgentEnvironment) {
      if (const char* v = std::getenv(name)) saved_env_.emplace_back(name, v);
      ::unsetenv(name);
    }
    for (const auto& [name, value] : request.environment) ::setenv(name.c_str(), value.c_str(), 1);
    std::fflush(stdout);
    std::fflush(stderr);
    for (int i = 0; i < 3; ++i) {
      own_fds_[i] = UniqueFd(::fcntl(i, F_DUPFD_CLOEXEC, 3));
      (void)::dup2(fds[static_cast<std::size_t>(i)].get(), i);
    }
    entered_ = true;
  }
  ~CallerScope() {
    if (entered_) {
      std::fflush(stdout);
      std::fflush(stderr);
      std::clearerr(stdout);  // a caller that closed its end leaves EPIPE behind
      std::clearerr(stderr);
      for (int i = 0; i < 3; ++i)
        if (own_fds_[i]) (void)::dup2(own_fds_[i].get(), i);
      for (const char* name : kAgentEnvironment) ::unsetenv(name);
      for (const auto& [name, value] : saved_env_) ::setenv(name.c_str(), value.c_str(), 1);
    }
    if (own_dir_) (void)::fchdir(own_dir_.get());
  }
  CallerScope(const CallerScope&) = delete;
  CallerScope& operator=(const CallerScope&) = delete;

 private:
  bool entered_ = false;
  UniqueFd own_dir_;
  UniqueFd own_fds_[3];
  std::vector<std::pair<std::string, std::string>> saved_env_;
};

std::string words(const std::vector<std::string>& arguments) {
  std::string s;
  for (const auto& a : arguments) s += (s.empty() ? "" : " ") + a;
  return s;
}

// Runs one accepted connection's call. Every outcome is one line of the agent's log, which
// names the worker (0 first): whether calls spilled over to further workers shows there.
void serve(int connection, ContextPool& pool, const AgentCallRunner& run, int worker) {
  ucred peer{};
  socklen_t len = sizeof peer;
  if (::getsockopt(connection, SOL_SOCKET, SO_PEERCRED, &peer, &len) != 0 || peer.uid != ::geteuid()) {
    (void)send_with_fds(connection, encode_reply({false, 0, "it belongs to another user"}), {});
    std::fprintf(stderr, "pmuctl agent: refused a call from uid %u (not this agent's user)\n",
                 static_cast<unsigned>(peer.uid));
    return;
  }
  std::string bytes;
  std::vector<UniqueFd> fds;
  if (!receive(connection, bytes, &fds)) {
    std::fprintf(stderr, "pmuctl agent: pid %d: no whole request (%s)\n", static_cast<int>(peer.pid),
                 std::strerror(errno));
    return;
  }
  std::string error;
  const auto request = decode_request(bytes, error);
  if (!request || fds.size() != 3) {
    if (request) error = "it came with " + std::to_string(fds.size()) + " file descriptors, not 3";
    (void)send_with_fds(connection, encode_reply({false, 0, "a bad request: " + error}), {});
    std::fprintf(stderr, "pmuctl agent: pid %d: a bad request: %s\n", static_cast<int>(peer.pid), error.c_str());
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  AgentReply reply;
  {
    CallerScope scope(*request, fds, error);
    if (error.empty()) {
      reply.status = run(request->arguments, pool, reply.declined);
      reply.ran = reply.declined.empty();
    } else {
      reply.declined = error;
    }
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (reply.ran)
    std::fprintf(stderr, "pmuctl agent: worker %d: pid %d: %s: exit %d in %.2f s\n", worker,
                 static_cast<int>(peer.pid), words(request->arguments).c_str(), reply.status, secs);
  else
    std::fprintf(stderr, "pmuctl agent: worker %d: pid %d: %s: declined (%s)\n", worker,
                 static_cast<int>(peer.pid), words(request->arguments).c_str(), reply.declined.c_str());
  if (!send_with_fds(connection, encode_reply(reply), {}))
    std::fprintf(stderr, "pmuctl agent: pid %d: its caller left before the answer\n", static_cast<int>(peer.pid));
}

// A listening socket at `path`, or an empty one after saying why. `lock` holds PATH.lock for
// the agent's life: two agents started at once cannot both take the path over.
UniqueFd listen_at(const std::string& path, UniqueFd& lock) {
  sockaddr_un addr{};
  if (path.size() >= sizeof addr.sun_path) {
    std::fprintf(stderr, "pmuctl agent: the socket path %s is longer than %zu bytes\n", path.c_str(),
                 sizeof addr.sun_path - 1);
    return UniqueFd();
  }
  // The directory (a user's runtime directory holds none yet); only this user enters it.
  const auto slash = path.rfind('/');
  if (slash != std::string::npos && slash > 0) (void)::mkdir(path.substr(0, slash).c_str(), 0700);
  const std::string lock_path = path + ".lock";
  lock = UniqueFd(::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600));
  if (!lock) {
    std::fprintf(stderr, "pmuctl agent: cannot open %s: %s\n", lock_path.c_str(), std::strerror(errno));
    return UniqueFd();
  }
  if (::flock(lock.get(), LOCK_EX | LOCK_NB) != 0 || connect_unix(path)) {
    std::fprintf(stderr, "pmuctl agent: another agent listens on %s\n", path.c_str());
    return UniqueFd();
  }
  // Nothing listens: a socket file left by an agent that was killed is taken over.
  struct stat st{};
  if (::lstat(path.c_str(), &st) == 0) {
    if (!S_ISSOCK(st.st_mode)) {
      std::fprintf(stderr, "pmuctl agent: %s exists and is not a socket: not replaced\n", path.c_str());
      return UniqueFd();
    }
    (void)::unlink(path.c_str());
  }
  addr.sun_family = AF_UNIX;
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  UniqueFd fd(::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0));
  const mode_t old_mask = ::umask(0177);  // the socket 0600: this user's calls only
  const bool bound = fd && ::bind(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  const int bind_errno = errno;
  ::umask(old_mask);
  if (!bound || ::listen(fd.get(), 64) != 0) {
    std::fprintf(stderr, "pmuctl agent: cannot listen on %s: %s\n", path.c_str(),
                 std::strerror(bound ? errno : bind_errno));
    return UniqueFd();
  }
  return fd;
}

// When each worker began the call it is serving (steady clock, ns; 0: idle), in memory the
// agent shares with its workers.
using BusySince = std::atomic<std::int64_t>;
static_assert(BusySince::is_always_lock_free, "shared between processes");
BusySince* g_busy = nullptr;  // kMaxWorkers of them, mapped before the workers are forked
constexpr int kMaxWorkers = 64;

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Worker `index` takes a call only when every worker before it has been on its current call
// for kSpillAfter: calls go to the first worker while it keeps up, so its endpoints, already
// matched at the aircraft (command endpoints stay matched, ContextPool), serve them, and each
// further worker, whose first calls announce endpoints of its own to every aircraft, only
// takes over from workers held up by an aircraft that does not answer. Over a radio link
// (700 ms round trip, 10 % loss) a call to an aircraft that answers takes 1 to 3.5 s, one
// that repairs a loss twice up to 5 s; a spilled call costs the link a worker's new
// endpoints and takes twice as long, so only a call past that waits for another worker.
constexpr auto kSpillAfter = std::chrono::seconds(5);
bool my_turn(int index) {
  if (!g_busy) return true;
  const std::int64_t now = steady_ns();
  for (int j = 0; j < index; ++j) {
    const std::int64_t since = g_busy[j].load();
    if (since == 0 || now - since < std::chrono::nanoseconds(kSpillAfter).count()) return false;
  }
  return true;
}

// One worker: takes calls from the shared listening socket until a stop signal, one at a time,
// with participants of its own. The socket is non-blocking: every idle worker wakes for a new
// connection, and the one whose turn it is (my_turn) and whose accept() gets it serves it.
void serve_calls(int listener, const GlobalOptions& settings, const AgentCallRunner& run, int index) {
  ContextPool pool(settings);
  // The participant from the start rather than at the worker's first call: the aircraft then
  // discover every worker's participant at once, and no call waits for that.
  try {
    (void)pool.context(kPmuctlParticipant, {});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmuctl agent: worker pid %d: %s (each call will say so)\n", static_cast<int>(::getpid()),
                 e.what());
  }
  while (!g_stop) {
    pollfd p{listener, POLLIN, 0};
    const int ready = ::poll(&p, 1, 200);  // the signal flag is looked at between waits
    if (ready <= 0) continue;
    if (!my_turn(index)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    UniqueFd connection(::accept4(listener, nullptr, nullptr, SOCK_CLOEXEC));
    if (!connection) continue;  // another worker took it
    if (g_busy) g_busy[index].store(steady_ns());
    serve(connection.get(), pool, run, index);
    if (g_busy) g_busy[index].store(0);
  }
}

// A worker process, forked before any DDS thread exists. It dies with the agent: a caller
// whose agent was killed must get no answer rather than one from an orphan.
pid_t start_worker(int listener, const GlobalOptions& settings, const AgentCallRunner& run, int index) {
  const pid_t agent = ::getpid();
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  (void)::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != agent) std::_Exit(1);  // the agent ended before the line above
  serve_calls(listener, settings, run, index);
  std::fflush(nullptr);
  std::exit(0);  // the participants are gone (serve_calls' pool); Fast DDS's own statics follow
}

}  // namespace

int run_agent(const GlobalOptions& settings, const std::string& socket, int workers, const AgentCallRunner& run) {
  UniqueFd lock;
  UniqueFd listener = listen_at(socket, lock);
  if (!listener) return 2;
  (void)::fcntl(listener.get(), F_SETFL, ::fcntl(listener.get(), F_GETFL) | O_NONBLOCK);
  struct sigaction sa{};
  sa.sa_handler = on_stop_signal;
  ::sigemptyset(&sa.sa_mask);
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  ::signal(SIGPIPE, SIG_IGN);  // a caller that closed its terminal must not end the agent

  // Line by line, as on a terminal: a caller's output and messages then interleave as they
  // would in a call on its own (stdout's buffering is chosen once, for the agent's own fd 1).
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::fprintf(stderr, "pmuctl agent: serving domain %d (%s) on %s, up to %d call%s at once\n", settings.domain,
               settings.network.summary.empty() ? "multicast discovery" : settings.network.summary.c_str(),
               socket.c_str(), workers, workers == 1 ? "" : "s");
  if (workers <= 1) {
    serve_calls(listener.get(), settings, run, 0);
  } else {
    workers = std::min(workers, kMaxWorkers);
    void* shared = ::mmap(nullptr, sizeof(BusySince) * kMaxWorkers, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (shared != MAP_FAILED) g_busy = new (shared) BusySince[kMaxWorkers]{};  // else every worker takes calls as they come
    std::vector<pid_t> pids;
    for (int i = 0; i < workers; ++i) pids.push_back(start_worker(listener.get(), settings, run, i));
    while (!g_stop) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      for (std::size_t i = 0; i < pids.size(); ++i) {
        pid_t& pid = pids[i];
        int status = 0;
        if (pid > 0 && ::waitpid(pid, &status, WNOHANG) != pid) continue;
        // A worker that failed or was killed: the others serve on, and a new one takes its place.
        if (pid > 0)
          std::fprintf(stderr, "pmuctl agent: worker pid %d ended (%s %d); a new one takes its place\n",
                       static_cast<int>(pid), WIFSIGNALED(status) ? "signal" : "exit",
                       WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status));
        if (g_busy) g_busy[i].store(0);  // a call it was serving ended with it
        pid = g_stop ? -1 : start_worker(listener.get(), settings, run, static_cast<int>(i));
      }
    }
    // Each worker ends after the call it is serving.
    for (const pid_t pid : pids)
      if (pid > 0) (void)::kill(pid, SIGTERM);
    for (const pid_t pid : pids)
      if (pid > 0) (void)::waitpid(pid, nullptr, 0);
  }
  (void)::unlink(socket.c_str());
  std::fprintf(stderr, "pmuctl agent: stopped\n");
  return 0;
}

}  // namespace pmu::tools
