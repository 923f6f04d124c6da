#pragma once
// Where pmu-mavlink meets the MAVLink network: one interface for its two kinds of endpoint,
// the UDP client (udp_endpoint.hpp) and the serial port (serial_endpoint.hpp). Both are
// non-blocking file descriptors the program's loop polls; both are opened at start-up, where
// alone they throw (LinkError, saying what and which address or device).
// Threads: one at a time (the program's loop).
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pmu::mavlink_bridge {

class LinkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a link counted since it opened; nothing here stops the program.
struct LinkCounters {
  std::uint64_t bytes_in = 0;
  std::uint64_t bytes_out = 0;
  std::uint64_t frames_out = 0;
  std::uint64_t send_failures = 0;      // a frame not sent whole: buffer full, peer unreachable
  std::uint64_t read_failures = 0;      // a read that failed (e.g. ICMP "port unreachable" on UDP)
  std::uint64_t foreign_datagrams = 0;  // UDP: a datagram from another address, dropped
};

class Endpoint {
 public:
  virtual ~Endpoint() = default;
  // The descriptor to poll for reading.
  virtual int fd() const noexcept = 0;
  // Appends every byte waiting now to `out` (never blocks); false when the link is gone for
  // good (a serial device unplugged), true otherwise, also when nothing waited.
  virtual bool read_available(std::vector<std::uint8_t>& out) = 0;
  // Sends one frame whole or counts it as a send failure (never blocks, never a part).
  virtual void send(const std::vector<std::uint8_t>& frame) = 0;
  // "udp 127.0.0.1:14550", "serial /dev/ttyAMA0 57600": for logs.
  virtual std::string describe() const = 0;
  const LinkCounters& counters() const noexcept { return counters_; }

 protected:
  LinkCounters counters_;
};

}  // namespace pmu::mavlink_bridge
