#pragma once
// The signals that stop a program (SIGINT and SIGTERM, and any others named), read instead of
// handled (docs/design.md: signals are read, never handled): the constructor blocks them in
// the calling thread, and every thread started after it inherits the blocked mask, so no
// handler ever runs inside Fast DDS's, a server's or a bus worker's threads, and a signal
// stays pending until this object reads it through its signalfd.
//
// Construct it in the main thread before any other thread starts (Fast DDS participants,
// servers, bus workers); a thread started earlier keeps its mask and would take the signal
// with its default action. Call its members from one thread at a time (a thread of its own
// may be the one that waits). The mask stays blocked after destruction:
// the threads that inherited it may still run.
//
//   pmu::transport::StopSignals stop;                 // first thing in main
//   ... start threads ...
//   while (!stop.wait_for(std::chrono::seconds(1))) { ... once a second ... }
#include <signal.h>

#include <chrono>
#include <initializer_list>

#include "pmu/transport/unique_fd.hpp"

namespace pmu::transport {

class StopSignals {
 public:
  // SIGINT and SIGTERM, plus `more` (e.g. SIGHUP for a daemon). Throws std::system_error when
  // the kernel refuses the signalfd (start-up only).
  explicit StopSignals(std::initializer_list<int> more = {});
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // Readable when a stop signal is pending, for a poll() loop that waits on other things too.
  int fd() const { return fd_.get(); }
  // The stop signal that arrived (read now or earlier), 0 when none: never blocks.
  int received();
  // Waits up to `timeout` for a stop signal: its number, or 0 when none came.
  int wait_for(std::chrono::milliseconds timeout);
  // Waits for a stop signal however long it takes: its number.
  int wait();
  // The blocked set, for a thread of its own that takes them with sigwait().
  const sigset_t& set() const { return set_; }

 private:
  sigset_t set_{};
  UniqueFd fd_;
  int received_ = 0;
};

}  // namespace pmu::transport
