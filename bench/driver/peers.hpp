#pragma once
// The references: the same Fast DDS, types, QoS profiles and transports as pmu-service,
// with nothing in between. Each runs as its own process (pmu_bench peer-writer|peer-echo).

#include <atomic>
#include <string>
#include <thread>

#include "pmu/dds_settings/transport_choice.hpp"
#include "pmu/transport/stop_signals.hpp"

namespace pmu::bench {

struct PeerOptions {
  int domain = 0;
  std::string qos_file;
  dds::Transport transport = dds::Transport::Default;
  double rate = 5;      // peer-writer: samples per second
  double seconds = 10;  // peer-writer: how long, once a reader is matched
  int units = 1;        // peer-telemetry: PMUs (instances per topic)
  double period = 0.1;  // peer-telemetry: seconds between one unit's rounds of five packets
};

// SIGTERM or SIGINT as a flag a run loop checks without a system call: a thread of its own
// waits for the signal. Construct it before Fast DDS starts its threads
// (pmu/transport/stop_signals.hpp says why), in the thread that also destroys it.
class StopFlag {
 public:
  StopFlag();
  ~StopFlag();
  StopFlag(const StopFlag&) = delete;
  StopFlag& operator=(const StopFlag&) = delete;
  const std::atomic<bool>& flag() const noexcept { return stop_; }
  explicit operator bool() const noexcept { return stop_; }
  void wait() const;  // until the signal came

 private:
  transport::StopSignals signals_;
  std::atomic<bool> stop_{false};
  std::thread waiter_;  // last: started once the signals are blocked
};

// A participant with one pmu/voltages writer (telemetry profile) writing samples that carry
// their write time (dds_probes.hpp) at `rate` for `seconds` once a reader is matched.
int peer_writer(const PeerOptions& o);

// A participant with a pmu/command reader and a pmu/command_reply writer (command profile)
// that answers each request at once, from the listener: a bare DDS request/reply.
// Runs until SIGTERM.
int peer_echo(const PeerOptions& o);

// Echoes every can_frame record arriving on fd 3 back to it, until the peer closes: the
// socketpair hop the service's frames take, alone (a blocking read, a wake-up, a write).
int peer_pong();

}  // namespace pmu::bench
