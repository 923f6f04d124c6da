#pragma once
// SocketCanBus: a CanBus on a Linux CAN_RAW socket (or on any fd that carries
// `struct can_frame` records, such as one end of a socketpair in tests).
//
// Purpose
//   The real bus under the service and pmu-sim. Frames and kernel receive timestamps come
//   in through recvmmsg until the socket is empty; error frames become bus state.
//
// Assumptions
//   * Classic CAN only (no CAN FD): records are exactly sizeof(struct can_frame).
//   * The socket is non-blocking; the caller's event loop polls fd(), which is the fd of
//     an EventLoop inside the bus (event_loop.hpp) watching the socket, so its number
//     survives a reopen. Events raised outside drain() wake that loop; drain() runs a turn
//     of it only then, and reads the socket on every call without asking epoll first.
//   * The Clock and SocketOps passed in outlive the bus: it keeps references to both
//     (main.cpp's SystemClock outlives every bus; system_socket_ops() lives for the program).
//   * One thread at a time (can_bus.hpp): in pmu-service, the bus worker's. The nested loop
//     has no thread of its own: drain() turns it on the caller's thread.
//
// Error handling (run time; construction throws std::system_error, see can_bus.hpp)
//   * ENETDOWN (link set down): keep the socket, state DOWN. Back to UP when a frame
//     arrives, a send succeeds, or maintain() sees IFF_UP on the interface again.
//   * ENODEV (interface removed): close the socket, state DOWN, send() returns NoDevice.
//     maintain() reopens and rebinds by interface name, at most once per reopen_interval,
//     once the name resolves again; a Reopened event and counters().reopens record it.
//     A zero-length read (the peer of an adopted fd closed) is treated the same way.
//   * ENOBUFS/EAGAIN on send: wait for POLLOUT (and, because POLLOUT reflects the socket
//     buffer rather than the device queue ENOBUFS is about, a short pause) until
//     max_wait, then SendStatus::Timeout.
//   * Error frames (CAN_ERR_CRTL warning/passive/active, CAN_ERR_BUSOFF,
//     CAN_ERR_RESTARTED) set the state; each is counted and reported as an ErrorFrame event.
//   * Kernel drops (SO_RXQ_OVFL) are counted in rx_drops.
//
// Security considerations
//   * See can_bus.hpp. The kernel filter limits what reaches this process; the userspace
//     check repeats it so an adopted fd is filtered the same way.

#include <linux/can.h>
#include <sys/socket.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pmu/transport/can_bus.hpp"
#include "pmu/transport/clock.hpp"
#include "pmu/transport/event_loop.hpp"
#include "pmu/transport/filters.hpp"
#include "pmu/transport/socket_ops.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::transport {

struct SocketCanOptions {
  std::vector<IdFilter> filters = default_filters(false);
  // Asked for with SO_RCVBUFFORCE, then SO_RCVBUF (which rmem_max caps). At 1 Mbit/s a
  // bus carries ~8000 frames/s; 1 MiB holds well over a second of them.
  int receive_buffer_bytes = 1 << 20;
  std::chrono::milliseconds reopen_interval{1000};
};

// What the socket set-up obtained, for the start-up log line.
struct SocketCanReport {
  int receive_buffer_bytes = 0;        // SO_RCVBUF as read back (the kernel doubles requests)
  bool receive_buffer_forced = false;  // SO_RCVBUFFORCE was permitted
  bool kernel_filters = false;         // CAN_RAW_FILTER and CAN_RAW_ERR_FILTER are installed
  bool kernel_timestamps = false;      // SO_TIMESTAMPNS is on
  bool drop_counting = false;          // SO_RXQ_OVFL is on
};

class SocketCanBus final : public CanBus {
  struct Private {
    explicit Private() = default;
  };

 public:
  // Opens CAN_RAW on `interface` ("can0"), installs filters, enables error frames,
  // timestamps and drop counting, and binds. An interface that does not exist (ENODEV) is
  // not an error: the bus starts DOWN without a socket (has_socket() false) and maintain()
  // binds it by name when it appears. Other failures throw std::system_error naming the
  // interface and the failing step, e.g. "can0: socket(PF_CAN, SOCK_RAW, CAN_RAW): Address
  // family not supported by protocol" on a kernel without CAN.
  static std::unique_ptr<SocketCanBus> open(const std::string& interface, const SocketCanOptions& options,
                                            const Clock& clock, SocketOps& ops = system_socket_ops());

  // Wraps an fd that already carries struct can_frame records. Socket options are applied
  // where the fd accepts them (report() says which); there is no interface to reopen, so
  // after ENODEV or end-of-stream the bus stays DOWN. Throws std::system_error only when
  // the EventLoop set-up (epoll, eventfd) fails or `fd` is not open.
  static std::unique_ptr<SocketCanBus> adopt(UniqueFd fd, const std::string& name, const SocketCanOptions& options,
                                             const Clock& clock, SocketOps& ops = system_socket_ops());

  // Public for make_unique; only the factories above can make a Private.
  SocketCanBus(Private, std::string name, std::string interface, const SocketCanOptions& options, const Clock& clock,
               SocketOps& ops);
  ~SocketCanBus() override;

  const std::string& name() const noexcept override { return name_; }
  int fd() const noexcept override { return loop_.fd(); }
  DrainResult drain(BusHandler& handler) override;
  SendResult send(const codec::CanFrame& frame, std::chrono::milliseconds max_wait) override;
  BusState state() const noexcept override { return state_; }
  BusCounters counters() const noexcept override { return counters_; }
  void maintain(std::chrono::steady_clock::time_point now) override;

  const SocketCanReport& report() const noexcept { return report_; }
  // True while a socket is open (false between ENODEV and a successful reopen).
  bool has_socket() const noexcept { return static_cast<bool>(socket_); }

 private:
  struct Delivery;  // the handler and tally of the drain() in progress
  struct Opened {
    UniqueFd socket;
    int error = 0;          // errno of the failed step, 0 on success
    const char* step = "";  // what failed, for messages
  };

  // Opens, configures and binds a CAN_RAW socket on interface_ (start-up and reopen).
  Opened open_bound_socket();
  int attach_socket(UniqueFd socket);
  void close_socket() noexcept;
  // Events raised inside drain() go straight to its handler; others wait for the next drain.
  void emit(const BusEvent& event, Delivery* out);
  void set_state(BusState next, Delivery* out);
  void lose_socket(int error, Delivery* out);
  void handle_receive_error(int error, Delivery& out);
  void handle_record(std::size_t index, Delivery& out);
  void handle_error_frame(const struct can_frame& raw, std::chrono::system_clock::time_point time, Delivery& out);
  void count_drops(std::uint32_t kernel_total) noexcept;
  SendResult fail_send(SendStatus status, int error) noexcept;
  BusEvent make_event(BusEventKind kind) const noexcept;

  static constexpr unsigned int kBatch = 64;
  // Room for SCM_TIMESTAMPNS (struct timespec) and SO_RXQ_OVFL (uint32) with headers.
  static constexpr std::size_t kControlBytes = 128;

  std::string name_;
  std::string interface_;  // empty for an adopted fd: nothing to reopen
  SocketCanOptions options_;
  const Clock& clock_;
  SocketOps& ops_;

  // Watches the socket; its fd is fd(). Woken while pending_events_ is not empty.
  EventLoop loop_;
  UniqueFd socket_;

  BusState state_ = BusState::Up;
  BusCounters counters_;
  SocketCanReport report_;
  std::vector<BusEvent> pending_events_;  // raised outside drain(), delivered by the next one
  std::uint32_t last_kernel_drops_ = 0;   // SO_RXQ_OVFL is a running total per socket
  std::chrono::steady_clock::time_point next_reopen_ = std::chrono::steady_clock::time_point::min();
  int last_reopen_error_ = 0;  // reported once, not once per attempt

  // recvmmsg buffers, kept here rather than on the stack of every drain().
  std::array<struct can_frame, kBatch> rx_frames_{};
  std::array<struct iovec, kBatch> rx_iov_{};
  std::array<struct mmsghdr, kBatch> rx_messages_{};
  struct alignas(struct cmsghdr) ControlBuffer {
    std::array<unsigned char, kControlBytes> bytes;
  };
  std::array<ControlBuffer, kBatch> rx_control_{};
};

}  // namespace pmu::transport
