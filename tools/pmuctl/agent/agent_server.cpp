#include "pmuctl/agent/agent_server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <iterator>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include "pmuctl/agent/agent_request.hpp"
#include "pmuctl/agent/unix_socket.hpp"

namespace pmu::tools {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop = true; }

constexpr int kMaxWorkers = 16;

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

std::uint64_t epoch_ns_now() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

// A worker's name in the log: its index (0 first), or "stop" for the stop lane.
std::string worker_name(int index) { return index < 0 ? "stop" : std::to_string(index); }

// Runs one call a worker was handed: the request the agent read, and its connection and the
// caller's three streams. The agent's log has a line when the worker takes the call and one
// for its outcome, each naming the worker: whether calls spilled over to further workers
// shows there, and a call that waits long for an aircraft shows as started while it waits.
void serve(int connection, const AgentRequest& request, const std::vector<UniqueFd>& streams, ContextPool& pool,
           const AgentCallRunner& run, int worker) {
  ucred peer{};
  socklen_t len = sizeof peer;
  (void)::getsockopt(connection, SOL_SOCKET, SO_PEERCRED, &peer, &len);
  // Before the caller's streams take stderr's place (CallerScope): this line is the agent's.
  std::fprintf(stderr, "pmuctl agent: worker %s: pid %d: %s: started\n", worker_name(worker).c_str(),
               static_cast<int>(peer.pid), words(request.arguments).c_str());
  const auto start = std::chrono::steady_clock::now();
  AgentReply reply;
  std::string error;
  {
    CallerScope scope(request, streams, error);
    if (error.empty()) {
      reply.status = run(request, pool, reply.declined);
      reply.ran = reply.declined.empty();
    } else {
      reply.declined = error;
    }
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (reply.ran)
    std::fprintf(stderr, "pmuctl agent: worker %s: pid %d: %s: exit %d in %.2f s\n", worker_name(worker).c_str(),
                 static_cast<int>(peer.pid), words(request.arguments).c_str(), reply.status, secs);
  else
    std::fprintf(stderr, "pmuctl agent: worker %s: pid %d: %s: declined (%s)\n", worker_name(worker).c_str(),
                 static_cast<int>(peer.pid), words(request.arguments).c_str(), reply.declined.c_str());
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
  struct stat st {};
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

// Worker `index` takes a call only when every worker before it has been on its current call
// for kSpillAfter: calls go to the first worker while it keeps up, so its endpoints, already
// matched at the aircraft (command endpoints stay matched, ContextPool), serve them, and each
// further worker, whose first calls announce endpoints of its own to every aircraft, only
// takes over from workers held up by an aircraft that does not answer. Over a radio link
// (700 ms round trip, 10 % loss) a call to an aircraft that answers takes 1 to 3.5 s, one
// that repairs a loss twice up to 5 s; a spilled call costs the link a worker's new
// endpoints and takes twice as long, so only a call past that waits for another worker.
// An engine stop never waits for this (the stop lane, below).
constexpr auto kSpillAfter = std::chrono::seconds(5);

// One worker process's loop: takes each call the agent hands it over `channel` (the request,
// then its connection and the caller's three streams), serves it with participants of its
// own, and says "done" on the channel, until a stop signal or the agent's end.
void serve_calls(int channel, const GlobalOptions& settings, const AgentCallRunner& run, int index) {
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
    pollfd p{channel, POLLIN, 0};
    if (::poll(&p, 1, 200) <= 0) continue;  // the signal flag is looked at between waits
    std::string bytes;
    std::vector<UniqueFd> fds;
    if (!receive(channel, bytes, &fds)) return;  // the agent ended
    std::string error;
    const auto request = decode_request(bytes, error);
    if (request && fds.size() == 4) {
      const std::vector<UniqueFd> streams(std::make_move_iterator(fds.begin() + 1), std::make_move_iterator(fds.end()));
      serve(fds[0].get(), *request, streams, pool, run, index);
    }
    fds.clear();  // the caller's connection closes here, after the answer
    std::fflush(nullptr);
    if (!send_with_fds(channel, "done", {})) return;
  }
}

// A call accepted and read by the agent, waiting for a worker.
struct Waiting {
  UniqueFd connection;
  std::string bytes;          // the request as it came, handed on to the worker
  std::vector<UniqueFd> fds;  // the caller's stdin, stdout, stderr
  AgentRequest request;
  pid_t pid = 0;
};

struct Worker {
  pid_t pid = -1;
  UniqueFd channel;                                                 // the agent's end of the worker's socketpair
  std::optional<std::chrono::steady_clock::time_point> busy_since;  // on a call since
};

// A worker process, forked before any DDS thread exists (the agent itself never makes one).
// It dies with the agent: a caller whose agent was killed must get no answer rather than one
// from an orphan. `others` are the agent's descriptors the worker must not keep (the other
// workers' channels, the listener, waiting callers' connections).
Worker start_worker(const GlobalOptions& settings, const AgentCallRunner& run, int index,
                    const std::vector<int>& others) {
  Worker w;
  int pair[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, pair) != 0) {
    std::fprintf(stderr, "pmuctl agent: cannot make a worker's channel: %s\n", std::strerror(errno));
    return w;
  }
  UniqueFd mine(pair[0]), its(pair[1]);
  const pid_t agent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    std::fprintf(stderr, "pmuctl agent: cannot start a worker: %s\n", std::strerror(errno));
    return w;
  }
  if (pid == 0) {
    (void)::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != agent) std::_Exit(1);  // the agent ended before the line above
    mine.reset();
    for (const int fd : others) (void)::close(fd);
    serve_calls(its.get(), settings, run, index);
    std::fflush(nullptr);
    std::exit(0);  // the participants are gone (serve_calls' pool); Fast DDS's own statics follow
  }
  w.pid = pid;
  w.channel = std::move(mine);
  return w;
}

// The agent: accepts each call, checks its caller, reads its request, and hands it to a
// worker (serve_calls) as the lanes allow; drops a waiting call whose caller left or whose
// wait ended. Never makes a DDS participant nor a thread, so it may fork workers at any time.
class Dispatcher {
 public:
  Dispatcher(int listener, const GlobalOptions& settings, const AgentCallRunner& run, int workers)
      : listener_(listener), settings_(settings), run_(run), workers_(static_cast<std::size_t>(workers)) {
    for (std::size_t i = 0; i < workers_.size(); ++i) replace(static_cast<int>(i));
    replace(kStop);
  }

  void run() {
    while (!g_stop) {
      std::vector<pollfd> polled{{listener_, POLLIN, 0}};
      for (const auto& w : workers_) polled.push_back({w.channel.get(), POLLIN, 0});
      polled.push_back({stop_.channel.get(), POLLIN, 0});
      for (const auto& c : waiting_) polled.push_back({c.connection.get(), 0, 0});  // POLLHUP: its caller left
      (void)::poll(polled.data(), polled.size(), 100);
      const auto now = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < workers_.size(); ++i)
        if (polled[1 + i].revents) heard_from(workers_[i]);
      if (polled[1 + workers_.size()].revents) heard_from(stop_);
      drop_waiting(polled, 2 + workers_.size());
      if (polled[0].revents & POLLIN) accept_calls();
      reap();
      hand_out(now);
    }
    // Each worker ends after the call it is serving; waiting calls get no answer (their
    // callers see the agent end, not run).
    waiting_.clear();
    for (auto* w : all())
      if (w->pid > 0) (void)::kill(w->pid, SIGTERM);
    for (auto* w : all())
      if (w->pid > 0) (void)::waitpid(w->pid, nullptr, 0);
  }

 private:
  static constexpr int kStop = -1;

  std::vector<Worker*> all() {
    std::vector<Worker*> v;
    for (auto& w : workers_) v.push_back(&w);
    v.push_back(&stop_);
    return v;
  }
  Worker& worker(int index) { return index == kStop ? stop_ : workers_[static_cast<std::size_t>(index)]; }

  // The agent's descriptors a new worker closes.
  std::vector<int> inherited() {
    std::vector<int> fds{listener_};
    for (auto* w : all())
      if (w->channel) fds.push_back(w->channel.get());
    for (const auto& c : waiting_) {
      fds.push_back(c.connection.get());
      for (const auto& f : c.fds) fds.push_back(f.get());
    }
    return fds;
  }

  void replace(int index) {
    Worker& w = worker(index);
    w.channel.reset();
    w.busy_since.reset();
    w = start_worker(settings_, run_, index, inherited());
  }

  // A worker said "done", or its channel closed (it died: reap() replaces it).
  void heard_from(Worker& w) {
    std::string bytes;
    if (receive(w.channel.get(), bytes)) w.busy_since.reset();
  }

  // Workers that died: replaced; a call one was serving ended with it (its caller sees the
  // connection close: "ended during the call", not run again).
  void reap() {
    for (int index = kStop; index < static_cast<int>(workers_.size()); ++index) {
      Worker& w = worker(index);
      int status = 0;
      if (w.pid > 0 && ::waitpid(w.pid, &status, WNOHANG) != w.pid) continue;
      if (w.pid > 0)
        std::fprintf(stderr, "pmuctl agent: worker pid %d ended (%s %d); a new one takes its place\n",
                     static_cast<int>(w.pid), WIFSIGNALED(status) ? "signal" : "exit",
                     WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status));
      replace(index);
    }
  }

  void accept_calls() {
    for (;;) {
      UniqueFd connection(::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC));
      if (!connection) return;
      ucred peer{};
      socklen_t len = sizeof peer;
      if (::getsockopt(connection.get(), SOL_SOCKET, SO_PEERCRED, &peer, &len) != 0 || peer.uid != ::geteuid()) {
        (void)send_with_fds(connection.get(), encode_reply({false, 0, "it belongs to another user", false, ""}), {});
        std::fprintf(stderr, "pmuctl agent: refused a call from uid %u (not this agent's user)\n",
                     static_cast<unsigned>(peer.uid));
        continue;
      }
      // The caller sends its request right after connecting; a caller that does not within
      // a moment is not waited for (the agent serves the others meanwhile).
      pollfd p{connection.get(), POLLIN, 0};
      Waiting c;
      if (::poll(&p, 1, 1000) <= 0 || !receive(connection.get(), c.bytes, &c.fds)) {
        std::fprintf(stderr, "pmuctl agent: pid %d: no whole request (%s)\n", static_cast<int>(peer.pid),
                     std::strerror(errno));
        continue;
      }
      std::string error;
      const auto request = decode_request(c.bytes, error);
      if (!request || c.fds.size() != 3) {
        if (request) error = "it came with " + std::to_string(c.fds.size()) + " file descriptors, not 3";
        (void)send_with_fds(connection.get(), encode_reply({false, 0, "a bad request: " + error, false, ""}), {});
        std::fprintf(stderr, "pmuctl agent: pid %d: a bad request: %s\n", static_cast<int>(peer.pid), error.c_str());
        continue;
      }
      c.connection = std::move(connection);
      c.request = *request;
      c.pid = peer.pid;
      waiting_.push_back(std::move(c));
    }
  }

  // Waiting calls whose caller left (its connection closed: Ctrl-C, `timeout`) or whose
  // caller's wait ended are not run, and the log says so (docs/safety.md H9).
  void drop_waiting(const std::vector<pollfd>& polled, std::size_t first) {
    const std::uint64_t now = epoch_ns_now();
    std::vector<Waiting> kept;
    for (std::size_t i = 0; i < waiting_.size(); ++i) {
      Waiting& c = waiting_[i];
      const bool left = i + first < polled.size() && (polled[i + first].revents & (POLLHUP | POLLERR));
      if (left) {
        std::fprintf(stderr, "pmuctl agent: pid %d: %s: dropped: its caller left before a worker was free\n",
                     static_cast<int>(c.pid), words(c.request.arguments).c_str());
      } else if (c.request.deadline_ns <= now) {
        AgentReply reply;
        reply.expired = true;
        reply.why_expired = "its wait (--timeout) ended before one of the agent's workers was free";
        (void)send_with_fds(c.connection.get(), encode_reply(reply), {});
        std::fprintf(stderr, "pmuctl agent: pid %d: %s: dropped: its caller's wait ended before a worker was free\n",
                     static_cast<int>(c.pid), words(c.request.arguments).c_str());
      } else {
        kept.push_back(std::move(c));
      }
    }
    waiting_ = std::move(kept);
  }

  bool free(const Worker& w) const { return w.pid > 0 && !w.busy_since; }

  // The worker for `c` now, or null. An engine stop goes to the stop lane, else to any free
  // worker, at once (docs/safety.md H4); another call to the first free worker all of whose
  // predecessors have been on their calls for kSpillAfter.
  Worker* worker_for(const Waiting& c, std::chrono::steady_clock::time_point now) {
    if (c.request.engine_stop) {
      if (free(stop_)) return &stop_;
      for (auto& w : workers_)
        if (free(w)) return &w;
      return nullptr;
    }
    for (auto& w : workers_) {
      if (free(w)) return &w;
      if (!w.busy_since || now - *w.busy_since < kSpillAfter) return nullptr;
    }
    return nullptr;
  }

  void hand_out(std::chrono::steady_clock::time_point now) {
    // Engine stops first, then the others in the order they came.
    std::stable_partition(waiting_.begin(), waiting_.end(), [](const Waiting& c) { return c.request.engine_stop; });
    std::vector<Waiting> kept;
    for (auto& c : waiting_) {
      Worker* w = worker_for(c, now);
      if (!w) {
        kept.push_back(std::move(c));
        continue;
      }
      const std::vector<int> fds{c.connection.get(), c.fds[0].get(), c.fds[1].get(), c.fds[2].get()};
      if (!send_with_fds(w->channel.get(), c.bytes, fds)) {
        kept.push_back(std::move(c));  // the worker died: its replacement takes the call
        continue;
      }
      w->busy_since = now;
      // The agent's copies close here: the worker holds the call's connection now.
    }
    waiting_ = std::move(kept);
  }

  int listener_;
  const GlobalOptions& settings_;
  const AgentCallRunner& run_;
  std::vector<Worker> workers_;
  Worker stop_;
  std::vector<Waiting> waiting_;
};

}  // namespace

int run_agent(const GlobalOptions& settings, const std::string& socket, int workers, const AgentCallRunner& run) {
  UniqueFd lock;
  UniqueFd listener = listen_at(socket, lock);
  if (!listener) return 2;
  (void)::fcntl(listener.get(), F_SETFL, ::fcntl(listener.get(), F_GETFL) | O_NONBLOCK);
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  ::sigemptyset(&sa.sa_mask);
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  ::signal(SIGPIPE, SIG_IGN);  // a caller that closed its terminal must not end the agent

  // Line by line, as on a terminal: a caller's output and messages then interleave as they
  // would in a call on its own (stdout's buffering is chosen once, for the agent's own fd 1).
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  workers = std::clamp(workers, 1, kMaxWorkers);
  std::fprintf(stderr, "pmuctl agent: serving domain %d (%s) on %s, up to %d call%s at once and an engine stop\n",
               settings.domain,
               settings.network.summary.empty() ? "multicast discovery" : settings.network.summary.c_str(),
               socket.c_str(), workers, workers == 1 ? "" : "s");
  {
    Dispatcher dispatcher(listener.get(), settings, run, workers);
    dispatcher.run();
  }
  (void)::unlink(socket.c_str());
  std::fprintf(stderr, "pmuctl agent: stopped\n");
  return 0;
}

}  // namespace pmu::tools
