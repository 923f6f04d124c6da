#include "pmu/transport/stop_signals.hpp"

#include <poll.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace pmu::transport {

StopSignals::StopSignals(std::initializer_list<int> more) {
  sigemptyset(&set_);
  sigaddset(&set_, SIGINT);
  sigaddset(&set_, SIGTERM);
  for (const int s : more) sigaddset(&set_, s);
  pthread_sigmask(SIG_BLOCK, &set_, nullptr);
  fd_ = UniqueFd(::signalfd(-1, &set_, SFD_CLOEXEC | SFD_NONBLOCK));
  if (!fd_) throw std::system_error(errno, std::generic_category(), "signalfd");
}

int StopSignals::received() {
  if (received_ != 0) return received_;
  signalfd_siginfo si{};
  if (::read(fd_.get(), &si, sizeof si) == static_cast<ssize_t>(sizeof si)) received_ = static_cast<int>(si.ssi_signo);
  return received_;
}

int StopSignals::wait_for(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (received() == 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
    if (left.count() <= 0) return 0;
    pollfd p{fd_.get(), POLLIN, 0};
    ::poll(&p, 1, static_cast<int>(left.count()));  // EINTR or a timeout: the loop decides
  }
  return received_;
}

int StopSignals::wait() {
  while (received() == 0) {
    pollfd p{fd_.get(), POLLIN, 0};
    ::poll(&p, 1, -1);
  }
  return received_;
}

}  // namespace pmu::transport
