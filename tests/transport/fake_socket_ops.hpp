#pragma once
// A SocketOps for tests: the real system calls underneath (on socketpairs), plus the
// failures a CAN interface produces and this kernel cannot (no AF_CAN here).
//
// AF_CAN emulation: open_can_raw() returns one end of a fresh SOCK_SEQPACKET socketpair and
// keeps the other in `peers`, so a test writes struct can_frame records "from the bus" and
// reads what the bus sent. CAN_RAW socket options and bind() are recorded, not applied.

#include <linux/can.h>

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pmu/transport/clock.hpp"
#include "pmu/transport/socket_ops.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::transport::test {

class FakeSocketOps final : public SocketOps {
 public:
  // With a clock, poll() does not wait: it returns the next of `poll_results` at once, or,
  // when there is none (and always for a plain wait of no fds), moves the clock by its
  // timeout and reports nothing ready, so a deadline passes at once. Without a clock,
  // poll() is the real call.
  explicit FakeSocketOps(ManualClock* clock = nullptr) : clock_(clock) {}

  // --- the emulated CAN interfaces ---
  bool can_supported = true;               // false: open_can_raw() fails with EAFNOSUPPORT
  std::map<std::string, int> interfaces;   // name -> ifindex; other names give ENODEV
  bool link_up = true;                     // what interface_up() reports
  bool allow_receive_buffer_force = true;  // false: SO_RCVBUFFORCE fails with EPERM

  // --- recorded ---
  std::vector<UniqueFd> peers;  // the test's end of every socket open_can_raw() made
  int opens = 0;                // open_can_raw() calls
  std::vector<struct can_filter> kernel_filters;
  can_err_mask_t error_mask = 0;
  int bound_ifindex = 0;
  std::vector<int> socket_options;  // SOL_SOCKET option names set, in order
  std::vector<int> poll_timeouts;   // timeout_ms of every poll() call
  std::deque<int> poll_results;     // see the constructor

  // --- injected failures ---
  std::deque<int> receive_errors;  // each receive() call pops one and fails with it
  std::deque<int> send_errors;     // likewise for send()
  int send_error_forever = 0;      // when non-zero, every send() fails with it
  // Appended as an SO_RXQ_OVFL control message (the kernel's running drop total) to the
  // next message received; a socketpair never produces one itself.
  std::optional<std::uint32_t> next_drop_total;

  int open_can_raw() override;
  int set_option(int fd, int level, int name, const void* value, socklen_t size) override;
  int get_option(int fd, int level, int name, void* value, socklen_t* size) override;
  int interface_index(const std::string& name) override;
  int interface_up(int fd, const std::string& name) override;
  int bind_can(int fd, int ifindex) override;
  int receive(int fd, struct mmsghdr* messages, unsigned int count) override;
  ssize_t send(int fd, const void* data, size_t size) override;
  int poll(struct pollfd* fds, nfds_t count, int timeout_ms) override;

 private:
  SocketOps& real_ = system_socket_ops();
  ManualClock* clock_;
};

}  // namespace pmu::transport::test
