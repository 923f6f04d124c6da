#pragma once
// SIGINT and SIGTERM for the long-running verbs (record, serve), taken by sigtimedwait in the
// main thread instead of a handler: constructed before Fast DDS or a server starts its
// threads, which inherit the blocked mask, so no handler ever runs inside them
// (docs/design.md: signals are read, never handled).

#include <signal.h>

#include <ctime>

namespace pmu::tools {

class StopSignals {
 public:
  StopSignals() {
    sigemptyset(&set_);
    sigaddset(&set_, SIGINT);
    sigaddset(&set_, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &set_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // Waits up to a second; true when SIGINT or SIGTERM arrived.
  bool wait_one_second() const {
    const timespec second{1, 0};
    const int sig = sigtimedwait(&set_, nullptr, &second);
    return sig == SIGINT || sig == SIGTERM;
  }

 private:
  sigset_t set_;
};

}  // namespace pmu::tools
