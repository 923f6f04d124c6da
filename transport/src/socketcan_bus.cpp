#include "pmu/transport/socketcan_bus.hpp"

#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>
#include <system_error>
#include <utility>

#include "pmu/transport/linux_frame.hpp"

namespace pmu::transport {
namespace {

// Error frames that change or explain the bus state. CAN_ERR_BUSERROR, CAN_ERR_PROT and
// CAN_ERR_ACK are left out: they arrive once per failed frame and can flood.
constexpr can_err_mask_t kErrorMask = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;

// POLLOUT reports room in the socket buffer; ENOBUFS is about the device queue, which no
// fd announces, so after a POLLOUT that did not help we pause this long before retrying.
constexpr int kNoBufferPauseMs = 1;

[[noreturn]] void throw_setup(int error, const std::string& name, const char* step) {
  throw std::system_error(error, std::generic_category(), name + ": " + step);
}

// The state an error frame announces, or nullopt when it says nothing about the state
// (a TX timeout, a controller overflow). linux/can/error.h documents the bits.
std::optional<BusState> state_from_error_frame(const struct can_frame& raw) noexcept {
  if ((raw.can_id & CAN_ERR_BUSOFF) != 0) return BusState::BusOff;
  if ((raw.can_id & CAN_ERR_CRTL) != 0) {
    const std::uint8_t status = raw.data[1];
    if ((status & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) return BusState::ErrorPassive;
    if ((status & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) return BusState::ErrorWarning;
    if ((status & CAN_ERR_CRTL_ACTIVE) != 0) return BusState::Up;
  }
  if ((raw.can_id & CAN_ERR_RESTARTED) != 0) return BusState::Up;
  return std::nullopt;
}

std::chrono::system_clock::time_point to_time_point(const struct timespec& ts) noexcept {
  const auto since_epoch = std::chrono::seconds{ts.tv_sec} + std::chrono::nanoseconds{ts.tv_nsec};
  return std::chrono::system_clock::time_point{
      std::chrono::duration_cast<std::chrono::system_clock::duration>(since_epoch)};
}

int enable(SocketOps& ops, int fd, int level, int name) {
  const int one = 1;
  return ops.set_option(fd, level, name, &one, sizeof(one));
}

struct SetupFailure {
  int error;
  const char* step;
};

// Applies the socket options. `can_socket`: the fd is AF_CAN, so the CAN_RAW options must
// succeed and any failure is returned; otherwise (an adopted fd) every option is best
// effort and `report` records what took.
std::optional<SetupFailure> configure(SocketOps& ops, int fd, const SocketCanOptions& options, bool can_socket,
                                      SocketCanReport& report) {
  report = SocketCanReport{};

  std::vector<struct can_filter> filters;
  filters.reserve(options.filters.size());
  for (const auto& f : options.filters) {
    const canid_t kind = f.extended ? CAN_EFF_FLAG : 0;
    filters.push_back({f.id | kind, f.mask | CAN_EFF_FLAG});
  }
  // No filter list means "everything", which is also the kernel's default.
  int rc = filters.empty() ? 0
                           : ops.set_option(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                                            static_cast<socklen_t>(filters.size() * sizeof(struct can_filter)));
  if (rc < 0 && can_socket) return SetupFailure{-rc, "setsockopt(CAN_RAW_FILTER)"};
  const can_err_mask_t error_mask = kErrorMask;
  const int rc_err = ops.set_option(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_mask, sizeof(error_mask));
  if (rc_err < 0 && can_socket) return SetupFailure{-rc_err, "setsockopt(CAN_RAW_ERR_FILTER)"};
  report.kernel_filters = rc == 0 && rc_err == 0;

  rc = enable(ops, fd, SOL_SOCKET, SO_TIMESTAMPNS);
  if (rc < 0 && can_socket) return SetupFailure{-rc, "setsockopt(SO_TIMESTAMPNS)"};
  report.kernel_timestamps = rc == 0;
  rc = enable(ops, fd, SOL_SOCKET, SO_RXQ_OVFL);
  if (rc < 0 && can_socket) return SetupFailure{-rc, "setsockopt(SO_RXQ_OVFL)"};
  report.drop_counting = rc == 0;

  // The buffer size is a wish, not a requirement: without CAP_NET_ADMIN the kernel caps
  // SO_RCVBUF at net.core.rmem_max, and we run with what we get and say so.
  if (options.receive_buffer_bytes > 0) {
    const int wanted = options.receive_buffer_bytes;
    report.receive_buffer_forced = ops.set_option(fd, SOL_SOCKET, SO_RCVBUFFORCE, &wanted, sizeof(wanted)) == 0;
    if (!report.receive_buffer_forced) ops.set_option(fd, SOL_SOCKET, SO_RCVBUF, &wanted, sizeof(wanted));
  }
  int obtained = 0;
  socklen_t size = sizeof(obtained);
  if (ops.get_option(fd, SOL_SOCKET, SO_RCVBUF, &obtained, &size) == 0) report.receive_buffer_bytes = obtained;
  return std::nullopt;
}

}  // namespace

struct SocketCanBus::Delivery {
  BusHandler& handler;
  DrainResult result;

  void event(const BusEvent& e) {
    ++result.events;
    handler.on_event(e);
  }
};

SocketCanBus::SocketCanBus(Private, std::string name, std::string interface, const SocketCanOptions& options,
                           const Clock& clock, SocketOps& ops)
    : name_(std::move(name)),
      interface_(std::move(interface)),
      options_(options),
      clock_(clock),
      ops_(ops),
      loop_(clock, name_) {}

SocketCanBus::~SocketCanBus() = default;

std::unique_ptr<SocketCanBus> SocketCanBus::open(const std::string& interface, const SocketCanOptions& options,
                                                 const Clock& clock, SocketOps& ops) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) throw_setup(EINVAL, interface, "not a valid interface name");
  auto bus = std::make_unique<SocketCanBus>(Private{}, interface, interface, options, clock, ops);
  Opened opened = bus->open_bound_socket();
  if (opened.error == ENODEV) {
    // The interface does not exist yet (a USB or SPI controller not probed, a vcan not
    // made): the service runs DOWN and maintain() binds by name once it appears, so the
    // unit needs no device ordering and another interface is a config change only.
    // Anything else (no CAN in the kernel, a refused option) stays a start-up error.
    bus->state_ = BusState::Down;
    bus->next_reopen_ = std::chrono::steady_clock::time_point::min();
    return bus;
  }
  if (opened.error != 0) throw_setup(opened.error, interface, opened.step);
  if (const int error = bus->attach_socket(std::move(opened.socket)); error != 0)
    throw_setup(error, interface, "epoll_ctl(socket)");
  // Bound to an interface that is administratively down: report it now rather than at
  // the first failed send.
  if (ops.interface_up(bus->socket_.get(), interface) == 0) bus->state_ = BusState::Down;
  return bus;
}

std::unique_ptr<SocketCanBus> SocketCanBus::adopt(UniqueFd fd, const std::string& name, const SocketCanOptions& options,
                                                  const Clock& clock, SocketOps& ops) {
  if (!fd) throw_setup(EBADF, name, "adopt");
  int type = 0;
  socklen_t size = sizeof(type);
  // recvmmsg needs a socket; anything else would fail on every wakeup.
  if (const int rc = ops.get_option(fd.get(), SOL_SOCKET, SO_TYPE, &type, &size); rc < 0)
    throw_setup(-rc, name, "adopt: getsockopt(SO_TYPE)");
  auto bus = std::make_unique<SocketCanBus>(Private{}, name, std::string{}, options, clock, ops);
  configure(ops, fd.get(), options, false, bus->report_);
  if (const int error = bus->attach_socket(std::move(fd)); error != 0) throw_setup(error, name, "epoll_ctl(socket)");
  return bus;
}

SocketCanBus::Opened SocketCanBus::open_bound_socket() {
  Opened opened;
  const int fd = ops_.open_can_raw();
  if (fd < 0) {
    opened.error = -fd;
    opened.step = "socket(PF_CAN, SOCK_RAW, CAN_RAW)";
    return opened;
  }
  UniqueFd socket{fd};
  if (const auto failure = configure(ops_, fd, options_, true, report_)) {
    opened.error = failure->error;
    opened.step = failure->step;
    return opened;
  }
  const int index = ops_.interface_index(interface_);
  if (index < 0) {
    opened.error = -index;
    opened.step = "if_nametoindex";
    return opened;
  }
  if (const int rc = ops_.bind_can(fd, index); rc < 0) {
    opened.error = -rc;
    opened.step = "bind";
    return opened;
  }
  opened.socket = std::move(socket);
  return opened;
}

int SocketCanBus::attach_socket(UniqueFd socket) {
  // No callback: drain() reads the socket itself on every call, so the loop only has to
  // make fd() readable while frames wait.
  if (const int error = loop_.watch(socket.get(), EventLoop::kReadable, {}); error != 0) return error;
  socket_ = std::move(socket);
  last_kernel_drops_ = 0;  // the running total starts again with each socket
  return 0;
}

void SocketCanBus::close_socket() noexcept {
  if (!socket_) return;
  // Before the close: epoll forgets an fd on close only when no duplicate of it remains.
  loop_.unwatch(socket_.get());
  socket_.reset();
}

BusEvent SocketCanBus::make_event(BusEventKind kind) const noexcept {
  BusEvent event;
  event.kind = kind;
  event.state = state_;
  event.previous = state_;
  event.time = clock_.system_now();
  return event;
}

void SocketCanBus::emit(const BusEvent& event, Delivery* out) {
  if (out != nullptr) {
    out->event(event);
    return;
  }
  pending_events_.push_back(event);
  loop_.wake();
}

void SocketCanBus::set_state(BusState next, Delivery* out) {
  if (next == state_) return;
  BusEvent event = make_event(BusEventKind::StateChanged);
  event.state = next;
  state_ = next;
  emit(event, out);
}

void SocketCanBus::lose_socket(int error, Delivery* out) {
  close_socket();
  // The interface is gone this moment, but try at the next maintain(): it may be a quick
  // driver reload, and the interval only spaces out the attempts that fail.
  next_reopen_ = std::chrono::steady_clock::time_point::min();
  last_reopen_error_ = 0;
  BusEvent event = make_event(BusEventKind::SocketError);
  event.error = error;
  emit(event, out);
  set_state(BusState::Down, out);
}

DrainResult SocketCanBus::drain(BusHandler& handler) {
  Delivery out{handler, {}};
  // The loop's wake-up is pending exactly while events are: only then is a turn (which
  // consumes it) worth its epoll_wait. The socket is read below either way.
  if (!pending_events_.empty()) loop_.run_once(std::chrono::milliseconds{0});
  // Swapped out first: a handler that sends can queue new events while we deliver.
  std::vector<BusEvent> queued;
  queued.swap(pending_events_);
  for (const auto& event : queued) out.event(event);

  while (socket_) {
    for (std::size_t i = 0; i < kBatch; ++i) {
      rx_iov_[i] = {&rx_frames_[i], sizeof(struct can_frame)};
      struct msghdr& header = rx_messages_[i].msg_hdr;
      header = {};
      header.msg_iov = &rx_iov_[i];
      header.msg_iovlen = 1;
      header.msg_control = rx_control_[i].bytes.data();
      header.msg_controllen = rx_control_[i].bytes.size();
      rx_messages_[i].msg_len = 0;
    }
    const int received = ops_.receive(socket_.get(), rx_messages_.data(), kBatch);
    if (received < 0) {
      const int error = -received;
      if (error == EINTR) continue;
      if (error != EAGAIN && error != EWOULDBLOCK) handle_receive_error(error, out);
      break;
    }
    const auto count = static_cast<std::size_t>(received);
    for (std::size_t i = 0; i < count && socket_; ++i) handle_record(i, out);
    // A short batch means the queue was empty when the kernel filled it; anything that
    // arrived since keeps the fd readable for the next wakeup.
    if (count < kBatch) break;
  }
  return out.result;
}

void SocketCanBus::handle_receive_error(int error, Delivery& out) {
  switch (error) {
    case ENETDOWN: {
      // The link was set down. The socket stays bound and works again when it comes up.
      BusEvent event = make_event(BusEventKind::SocketError);
      event.error = error;
      emit(event, &out);
      set_state(BusState::Down, &out);
      break;
    }
    case ENODEV:
      lose_socket(error, &out);  // the interface was removed; the binding died with it
      break;
    default: {
      BusEvent event = make_event(BusEventKind::SocketError);
      event.error = error;
      emit(event, &out);
      break;
    }
  }
}

void SocketCanBus::handle_record(std::size_t index, Delivery& out) {
  struct mmsghdr& message = rx_messages_[index];
  if (message.msg_len == 0) {
    // End of stream: only an adopted stream-like fd does this (its peer closed). Left
    // alone, the fd would stay readable forever.
    lose_socket(ECONNRESET, &out);
    return;
  }
  std::optional<std::chrono::system_clock::time_point> kernel_time;
  for (struct cmsghdr* c = CMSG_FIRSTHDR(&message.msg_hdr); c != nullptr; c = CMSG_NXTHDR(&message.msg_hdr, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SCM_TIMESTAMPNS && c->cmsg_len >= CMSG_LEN(sizeof(struct timespec))) {
      struct timespec ts {};
      std::memcpy(&ts, CMSG_DATA(c), sizeof(ts));
      kernel_time = to_time_point(ts);
    } else if (c->cmsg_type == SO_RXQ_OVFL && c->cmsg_len >= CMSG_LEN(sizeof(std::uint32_t))) {
      std::uint32_t total = 0;
      std::memcpy(&total, CMSG_DATA(c), sizeof(total));
      count_drops(total);
    }
  }
  if (message.msg_len != sizeof(struct can_frame) || (message.msg_hdr.msg_flags & MSG_TRUNC) != 0) {
    ++counters_.rx_invalid;
    return;
  }
  const struct can_frame& raw = rx_frames_[index];
  const auto time = kernel_time.value_or(clock_.system_now());
  if ((raw.can_id & CAN_ERR_FLAG) != 0) {
    handle_error_frame(raw, time, out);
    return;
  }
  const auto frame = from_linux(raw);
  if (!frame) {
    ++counters_.rx_invalid;
    return;
  }
  // Any frame at all proves the link carries traffic again.
  if (state_ == BusState::Down) set_state(BusState::Up, &out);
  if (!accepts(options_.filters, *frame)) {
    ++counters_.rx_filtered;
    return;
  }
  ++counters_.rx_frames;
  ++out.result.frames;
  out.handler.on_frame(ReceivedFrame{*frame, time, kernel_time.has_value()});
}

void SocketCanBus::handle_error_frame(const struct can_frame& raw, std::chrono::system_clock::time_point time,
                                      Delivery& out) {
  ++counters_.error_frames;
  BusEvent event = make_event(BusEventKind::ErrorFrame);
  event.time = time;
  event.error_class = raw.can_id & CAN_ERR_MASK;
  std::copy_n(raw.data, std::min<std::size_t>(raw.len, event.error_data.size()), event.error_data.begin());
  emit(event, &out);
  if (const auto next = state_from_error_frame(raw)) set_state(*next, &out);
}

void SocketCanBus::count_drops(std::uint32_t kernel_total) noexcept {
  // Unsigned subtraction also covers the kernel's 32-bit counter wrapping.
  counters_.rx_drops += static_cast<std::uint32_t>(kernel_total - last_kernel_drops_);
  last_kernel_drops_ = kernel_total;
}

SendResult SocketCanBus::fail_send(SendStatus status, int error) noexcept {
  ++counters_.tx_failures;
  return SendResult{status, error};
}

SendResult SocketCanBus::send(const codec::CanFrame& frame, std::chrono::milliseconds max_wait) {
  if (!is_sendable(frame)) return fail_send(SendStatus::InvalidFrame, EINVAL);
  if (!socket_) return fail_send(SendStatus::NoDevice, ENODEV);
  const struct can_frame raw = to_linux(frame);
  const auto deadline = clock_.steady_now() + max_wait;
  for (;;) {
    const ssize_t sent = ops_.send(socket_.get(), &raw, sizeof(raw));
    if (sent == static_cast<ssize_t>(sizeof(raw))) {
      ++counters_.tx_frames;
      if (state_ == BusState::Down) set_state(BusState::Up, nullptr);
      return SendResult{};
    }
    // A short write of a datagram cannot happen on CAN_RAW; treat it as an I/O error.
    const int error = sent < 0 ? static_cast<int>(-sent) : EIO;
    switch (error) {
      case EINTR: continue;
      case ENOBUFS:
      case EAGAIN: {
        const auto now = clock_.steady_now();
        if (now >= deadline) return fail_send(SendStatus::Timeout, error);
        const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - now);
        const int wait_ms = static_cast<int>(std::max<decltype(left.count())>(left.count(), 1));
        struct pollfd writable {
          socket_.get(), POLLOUT, 0
        };
        const int ready = ops_.poll(&writable, 1, wait_ms);
        if (ready > 0 && error == ENOBUFS) ops_.poll(nullptr, 0, std::min(wait_ms, kNoBufferPauseMs));
        continue;
      }
      case ENETDOWN: set_state(BusState::Down, nullptr); return fail_send(SendStatus::Down, error);
      case ENODEV: lose_socket(error, nullptr); return fail_send(SendStatus::NoDevice, error);
      default: return fail_send(SendStatus::Error, error);
    }
  }
}

void SocketCanBus::maintain(std::chrono::steady_clock::time_point now) {
  if (interface_.empty()) return;  // an adopted fd has nothing to reopen or ask about
  if (!socket_) {
    if (now < next_reopen_) return;
    next_reopen_ = now + options_.reopen_interval;
    Opened opened = open_bound_socket();
    int error = opened.error;
    if (error == 0) error = attach_socket(std::move(opened.socket));
    if (error != 0) {
      // ENODEV is the expected answer while the interface is away; other failures are
      // reported once each rather than every interval.
      if (error != ENODEV && error != last_reopen_error_) {
        BusEvent event = make_event(BusEventKind::SocketError);
        event.error = error;
        emit(event, nullptr);
      }
      last_reopen_error_ = error;
      return;
    }
    ++counters_.reopens;
    emit(make_event(BusEventKind::Reopened), nullptr);
  }
  if (state_ == BusState::Down) {
    // ENETDOWN left the socket bound; only a frame or this check tells us the link is back.
    if (ops_.interface_up(socket_.get(), interface_) == 1) set_state(BusState::Up, nullptr);
  }
}

}  // namespace pmu::transport
