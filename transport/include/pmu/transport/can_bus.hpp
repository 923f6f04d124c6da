#pragma once
// CanBus: how the service talks to one CAN bus.
//
// Purpose
//   The one seam between the service and the wire. SocketCanBus (socketcan_bus.hpp) is the
//   real bus; SimBus (sim_bus.hpp) is an in-process bus for tests and `--bus sim`. Both
//   carry codec::CanFrame and know nothing of the protocol above the identifier filter.
//
// Assumptions
//   * The service runs one event loop per bus (EventLoop, event_loop.hpp; any epoll loop
//     will do). It registers fd() for EPOLLIN once; fd() stays the same number for the
//     life of the bus, even when the socket underneath is closed and reopened, so the loop
//     never re-registers anything.
//   * fd() is level-triggered readable while frames or events are pending. Each wakeup the
//     loop calls drain(), which delivers EVERY pending frame and event (a kernel wakeup costs
//     far more than a frame: docs/design.md, "Drain every pending frame per wakeup"), then
//     returns.
//   * The loop calls maintain(now) periodically (every few hundred ms is plenty) for the
//     work no fd announces: reopening a vanished interface, noticing a link that came up.
//   * One thread uses a bus at a time. (SimBus endpoints of one network may be used from
//     different threads; see sim_bus.hpp.)
//   * Receive timestamps are the kernel's (SO_TIMESTAMPNS) for SocketCAN and the injected
//     clock's for SimBus; they are wall-clock times, as DDS source timestamps are.
//
// Error handling
//   * Opening a bus throws (std::system_error with the interface name and strerror) when
//     it cannot be set up: that is start-up, and main turns it into a message and an exit
//     status. After that nothing throws: send() returns a SendResult, receive-side failures
//     become BusEvents and counters, malformed records are counted and skipped.
//   * A bus that goes away is not an error to propagate: state() says DOWN, send() fails
//     fast, and the bus comes back by itself (on frames, link up, or reopen in maintain()).
//
// Security considerations
//   * Everything on a CAN bus is unauthenticated: any node can send any identifier. The
//     filter keeps foreign identifiers out of the upper layers, and the codec treats every
//     payload as untrusted; nothing here trusts a frame's contents.
//   * A flooding node can only fill our receive queue: the kernel drops the excess and
//     rx_drops counts it. drain() reads until the queue is empty, so a flood costs CPU but
//     cannot grow memory.
//   * Opening AF_CAN sockets needs no privilege; SO_RCVBUFFORCE needs CAP_NET_ADMIN and is
//     only tried, never required.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "pmu/codec/can_frame.hpp"

namespace pmu::transport {

// The contract's Health.bus_state (interface.md).
enum class BusState : std::uint8_t {
  Up,            // error-active: sending and receiving normally
  ErrorWarning,  // a controller error counter passed 96
  ErrorPassive,  // a controller error counter passed 127
  BusOff,        // the controller left the bus; it may restart by itself
  Down,          // the interface is down or gone (or the simulated bus was taken down)
};
// "UP", "ERROR_WARNING", "ERROR_PASSIVE", "BUS_OFF", "DOWN".
std::string_view to_string(BusState state) noexcept;

// Monotonic since the bus was constructed (across reopens).
struct BusCounters {
  std::uint64_t rx_frames = 0;     // data frames delivered to a handler
  std::uint64_t tx_frames = 0;     // frames the kernel (or the simulated bus) accepted
  std::uint64_t rx_drops = 0;      // frames lost because our receive queue was full (SO_RXQ_OVFL)
  std::uint64_t rx_filtered = 0;   // frames of identifiers outside the filter, discarded
  std::uint64_t rx_invalid = 0;    // records that were not a whole struct can_frame
  std::uint64_t error_frames = 0;  // controller error frames (CAN_ERR_FLAG)
  std::uint64_t tx_failures = 0;   // send() calls that returned anything but Sent
  std::uint64_t reopens = 0;       // times the socket was reopened after its interface vanished
};

struct ReceivedFrame {
  codec::CanFrame frame;
  std::chrono::system_clock::time_point timestamp;
  // True when the kernel stamped the frame (SO_TIMESTAMPNS). Otherwise the timestamp is the
  // injected clock's: SimBus's send time, or drain time for an fd without timestamps.
  bool kernel_timestamp = false;
};

enum class BusEventKind : std::uint8_t {
  StateChanged,  // state() changed from `previous` to `state`
  ErrorFrame,    // a controller error frame; error_class and error_data say what it was
  SocketError,   // a receive or reopen failed with `error` (an errno value)
  Reopened,      // the interface came back; a new socket is bound to it
};

struct BusEvent {
  BusEventKind kind = BusEventKind::StateChanged;
  BusState state = BusState::Up;             // the state after this event
  BusState previous = BusState::Up;          // the state before it
  int error = 0;                             // errno, for SocketError
  std::uint32_t error_class = 0;             // can_id & CAN_ERR_MASK (linux/can/error.h), for ErrorFrame
  std::array<std::uint8_t, 8> error_data{};  // the error frame's payload, for ErrorFrame
  std::chrono::system_clock::time_point time;
};

// What drain() hands its results to. Called synchronously from drain(), in arrival order.
class BusHandler {
 public:
  virtual void on_frame(const ReceivedFrame& frame) = 0;
  virtual void on_event(const BusEvent& event) = 0;

 protected:
  ~BusHandler() = default;
};

struct DrainResult {
  std::size_t frames = 0;  // on_frame calls made
  std::size_t events = 0;  // on_event calls made
};

enum class SendStatus : std::uint8_t {
  Sent,          // accepted for transmission
  InvalidFrame,  // id out of range for its kind, or length > 8: nothing was sent
  Timeout,       // the transmit queue stayed full (ENOBUFS/EAGAIN) until max_wait passed
  Down,          // the interface is down (ENETDOWN) or the simulated bus is DOWN
  BusOff,        // the simulated bus is BUS_OFF
  NoDevice,      // the interface is gone (ENODEV); maintain() reopens it when it returns
  Error,         // any other failure; `error` holds the errno
  Fenced,        // not sent: this instance of a hot-standby pair does not own the bus
};
// "sent", "invalid frame", "timeout", "bus down", "bus off", "no device", "error",
// "not the bus owner".
std::string_view to_string(SendStatus status) noexcept;

struct SendResult {
  SendStatus status = SendStatus::Sent;
  int error = 0;  // the errno behind a failure, 0 when there was none
  bool ok() const noexcept { return status == SendStatus::Sent; }
};

// True when the frame can be put on a classic CAN bus: the id fits its kind and length <= 8.
bool is_sendable(const codec::CanFrame& frame) noexcept;

class CanBus {
 public:
  virtual ~CanBus() = default;
  // Buses are owned through std::unique_ptr and their address may be registered elsewhere
  // (a simulated network): they neither copy nor move.
  CanBus(const CanBus&) = delete;
  CanBus& operator=(const CanBus&) = delete;
  CanBus(CanBus&&) = delete;
  CanBus& operator=(CanBus&&) = delete;

  // The service's name for the bus ("can0", "sim0"): used in DDS keys and messages.
  virtual const std::string& name() const noexcept = 0;

  // Readable (EPOLLIN, level-triggered) while drain() has something to deliver. Stable.
  virtual int fd() const noexcept = 0;

  // Delivers every pending frame and event to `handler`, then returns. Never blocks.
  virtual DrainResult drain(BusHandler& handler) = 0;

  // Queues one frame for transmission. When the transmit queue is full, waits for room
  // until `max_wait` has passed (0: try once). Never throws.
  virtual SendResult send(const codec::CanFrame& frame, std::chrono::milliseconds max_wait) = 0;

  virtual BusState state() const noexcept = 0;
  virtual BusCounters counters() const noexcept = 0;

  // Periodic work that no fd announces (reopen, link checks). `now` is the loop's reading
  // of the injected clock. Results arrive through the next drain() as events.
  virtual void maintain(std::chrono::steady_clock::time_point now) = 0;

 protected:
  CanBus() = default;
};

}  // namespace pmu::transport
