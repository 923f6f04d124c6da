#pragma once
// DeviceSession: the service's conversation with one PMU.
//
// The PMU's answers carry no sequence number, only the packet id they answer, so requests
// to one device are strictly serialised: one in flight, the rest queued in order. A request
// that expects an answer is matched by (address, packet id, data-carrying frame); it is
// retried (idempotent gets only) and ends in Timeout when the device stays silent.
//
// Life of a session: READING (serial, firmware, every stored parameter, outputs, generation)
// -> publishes info and config -> RUNNING (streaming: listen; polling: ask every period,
// with 0x0F from firmware 1.14 and single gets before). Health follows frame age:
// ONLINE while a frame came within stale_periods x period, STALE until offline_periods x
// period, then OFFLINE; a frame after OFFLINE re-reads info and config (the unit may have
// been swapped or reset).
//
// No I/O and no clock of its own: frames go out through a send callback, time comes in
// through every call, so tests drive it with a fake clock.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>

#include "pmu/codec/decode.hpp"
#include "pmu/service/config.hpp"
#include "pmu/service/device_state.hpp"

namespace pmu::service {

using SteadyTime = std::chrono::steady_clock::time_point;
using WallTime = std::chrono::system_clock::time_point;

enum class RequestStatus : std::uint8_t {
  Answered,    // the device replied; `reply` holds it
  Sent,        // no reply expected (a set or command) and the bus accepted the frame
  Timeout,     // no reply after every try
  SendFailed,  // the bus refused the frame (down, gone, queue full)
  Expired,     // its expiry passed while it waited in the queue: never sent
};

struct RequestOutcome {
  RequestStatus status = RequestStatus::Sent;
  std::optional<codec::PmuMessage> reply;
  transport::SendResult send;  // the last send attempt
};

struct Request {
  codec::CanFrame frame;
  // Packet id of the expected answer; nullopt when the device sends none (sets, commands).
  std::optional<codec::PacketId> reply;
  unsigned retries = 0;  // extra tries; only for requests that are safe to repeat
  std::function<void(const RequestOutcome&)> done;
  int tag = 0;  // the session's own requests (reading, polling) are tagged to find them
  // Not sent after this time (a command that waited too long behind others is dropped).
  std::optional<std::chrono::steady_clock::time_point> expires;
};

class DeviceSession {
 public:
  using SendFn = std::function<transport::SendResult(const codec::CanFrame&)>;

  DeviceSession(DeviceKey key, DeviceConfig config, const Timeouts& timeouts, StateSink& sink, SendFn send,
                SteadyTime now);

  const DeviceKey& key() const noexcept { return key_; }
  // A frame from this device's address, already decoded without firmware knowledge; the
  // session re-decodes firmware-dependent packets once it knows the firmware.
  void on_frame(const codec::CanFrame& frame, SteadyTime now, WallTime received);
  // A frame from this address that did not decode.
  void on_decode_error() noexcept { ++health_.decode_errors; }
  void on_bus_state(transport::BusState state, SteadyTime now);
  void on_bus_counters(const transport::BusCounters& counters) noexcept;
  // Timeouts, polling, health. Call at least every few tens of ms.
  void tick(SteadyTime now);

  // Queues a request behind those already waiting.
  void submit(Request request, SteadyTime now);
  // Queues a request ahead of everything waiting (ENGINE_STOP must not wait behind a queue).
  void submit_front(Request request, SteadyTime now);
  // Reads identity and every stored value again (after a reset).
  void reread(SteadyTime now) { start_reading(now); }

  // During a CAN address change, frames from `alias` belong to this session too; readdress()
  // moves the session to its new address once the change is verified.
  void set_alias(std::optional<std::uint16_t> alias) noexcept { alias_ = alias; }
  std::optional<std::uint16_t> alias() const noexcept { return alias_; }
  void readdress(std::uint16_t address) noexcept {
    key_.address = address;
    alias_.reset();
  }

  // The latest time any call brought: callbacks that queue follow-up work use it.
  SteadyTime now() const noexcept { return now_; }
  const ConfigState& config_state() const noexcept { return config_; }
  const std::optional<InfoState>& info() const noexcept { return info_; }
  std::optional<codec::FirmwareVersion> firmware() const noexcept;
  const HealthReport& health() const noexcept { return health_; }
  bool ready() const noexcept { return phase_ == Phase::Running; }
  std::size_t queued() const noexcept { return queue_.size() + (in_flight_ ? 1 : 0); }

 private:
  enum class Phase : std::uint8_t { Reading, Running };
  static constexpr int kReadingTag = 1;
  static constexpr int kPollTag = 2;

  void start_reading(SteadyTime now);
  void on_reading_done(const RequestOutcome& outcome, std::uint64_t round);
  void configure_streaming();
  void poll(SteadyTime now);
  void send_next(SteadyTime now);
  void finish(RequestOutcome outcome, SteadyTime now);
  void absorb(const codec::PmuMessage& m);
  void update_health(SteadyTime now, bool force);
  std::chrono::milliseconds period() const noexcept;

  DeviceKey key_;
  DeviceConfig config_cfg_;
  Timeouts timeouts_;
  StateSink& sink_;
  SendFn send_;

  Phase phase_ = Phase::Reading;
  std::uint64_t reading_round_ = 0;
  unsigned reading_left_ = 0;  // gets of the current reading round still to be answered
  bool reading_failed_ = false;
  ConfigState config_;
  std::optional<InfoState> info_;
  HealthReport health_;

  std::deque<Request> queue_;
  std::optional<Request> in_flight_;
  unsigned attempts_ = 0;
  SteadyTime deadline_{};

  bool pumping_ = false;
  std::optional<std::uint16_t> alias_;
  SteadyTime now_{};  // the latest time any call brought
  SteadyTime created_{};
  std::optional<SteadyTime> last_rx_;
  SteadyTime next_poll_{};
  SteadyTime next_health_{};
  SteadyTime retry_reading_at_{};
};

}  // namespace pmu::service
