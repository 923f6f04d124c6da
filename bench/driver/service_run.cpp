#include "service_run.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <stdexcept>

#include "pacer.hpp"

namespace pmu::bench {

const char* transport_name(dds::Transport t) noexcept {
  switch (t) {
    case dds::Transport::UdpOnly: return "udp";
    case dds::Transport::ShmOnly: return "shm";
    case dds::Transport::Default: break;
  }
  return "default";
}

ServiceRun::ServiceRun(const Settings& s, int domain, dds::Transport transport, const std::string& tag,
                       FakePmuLoad load) {
  const std::string config = s.workdir + "/" + tag + ".yaml";
  log_ = s.workdir + "/" + tag + ".log";
  notify_path_ = s.workdir + "/" + tag + ".notify";
  {
    std::ofstream c(config);
    // The fake PMUs streaming every packet at their period; commands unthrottled enough
    // for sequential round trips.
    c << "domain: " << domain << "\n"
      << "qos_file: " << s.qos_file << "\n"
      << "dds_transport: " << transport_name(transport) << "\n"
      << "log_level: warn\n"
      << "policy:\n  rate_limit: 1000\n  burst: 10000\n"
      << "buses:\n  - interface: can0\n    devices:\n";
    for (unsigned a = 1; a <= load.units; ++a)
      c << "      - address: " << a << "\n        period: " << load.period_tenths / 10 << "." << load.period_tenths % 10
        << "\n";
    if (!c) throw std::runtime_error("cannot write " + config);
  }
  notify_ = transport::UniqueFd(::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (notify_path_.size() >= sizeof addr.sun_path) throw std::runtime_error("work folder path too long for a socket");
  std::strncpy(addr.sun_path, notify_path_.c_str(), sizeof addr.sun_path - 1);
  ::unlink(notify_path_.c_str());
  if (::bind(notify_.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0)
    throw std::runtime_error("cannot bind " + notify_path_ + ": " + std::strerror(errno));

  int ends[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, ends) != 0)
    throw std::runtime_error(std::string("socketpair: ") + std::strerror(errno));
  transport::UniqueFd ours(ends[0]), theirs(ends[1]);
  pmu_ = std::make_unique<FakePmu>(std::move(ours), load);
  process_ = std::make_unique<ChildProcess>(
      std::vector<std::string>{s.service_exe, "--config", config, "--bus", "fd:3"},
      std::vector<std::string>{"NOTIFY_SOCKET=" + notify_path_}, std::move(theirs), log_);
}

ServiceRun::~ServiceRun() {
  process_.reset();  // stops the service before its bus peer goes away
  pmu_.reset();
  ::unlink(notify_path_.c_str());
}

std::optional<std::int64_t> ServiceRun::wait_ready(std::chrono::milliseconds timeout) {
  const std::int64_t until = steady_ns() + std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
  char buf[4096];
  for (;;) {
    const std::int64_t left = (until - steady_ns()) / 1000000;
    if (left <= 0) return std::nullopt;
    pollfd p{notify_.get(), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(std::min<std::int64_t>(left, 100))) <= 0) {
      check_alive();
      continue;
    }
    const ssize_t n = ::recv(notify_.get(), buf, sizeof buf - 1, 0);
    const std::int64_t at = steady_ns();
    if (n <= 0) continue;
    buf[n] = '\0';
    if (std::strstr(buf, "READY=1")) {
      // The service reports its status every second, and a datagram socket nobody reads
      // fills: its sd_notify then blocks its main loop, which no longer sees SIGTERM, and a
      // SIGKILL later leaves its shared-memory ports behind to fail the next service's
      // discovery in this domain. Without the socket, sd_notify fails at once.
      notify_.reset();
      ::unlink(notify_path_.c_str());
      return at;
    }
  }
}

void ServiceRun::check_alive() {
  if (!process_->running()) throw std::runtime_error("pmu-service exited (" + log_ + "): " + tail(log_));
}

std::string ServiceRun::log_tail() const { return log_ + ": " + tail(log_, 20); }

}  // namespace pmu::bench
